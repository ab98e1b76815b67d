#pragma once
// The report of a campaign (docs/campaign.md): report.md with the isolation outcome matrix (kind ×
// gyro), delays against the CUSUM theory, false alarms per hour, the pointing error distribution and
// every wrong exclusion; PNG plots (gnuplot) of the delays, the outcomes and the pointing errors.

#include <string>

#include "tetra/core/result.hpp"

namespace tetra::cli {

Status write_campaign_report(const std::string& runs_csv, const std::string& out_dir);

}  // namespace tetra::cli
