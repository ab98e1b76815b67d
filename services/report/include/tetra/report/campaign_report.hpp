#pragma once
// Writes a campaign's report (tetra/sim/campaign_report.hpp) into its folder: report.md and the PNG
// plots, drawn with gnuplot.

#include <string>

#include "tetra/core/result.hpp"
#include "tetra/sim/campaign_report.hpp"

namespace tetra::report {

//! The report of `runs_csv` into `out_dir`.
Status write_campaign_report(const std::string& runs_csv, const std::string& out_dir,
                             const sim::CampaignReportOptions& options);
//! The report of the campaign `spec` in `out_dir` (its runs.csv), with the options the spec asks for.
Status write_campaign_report(const sim::CampaignSpec& spec, const std::string& out_dir);

}  // namespace tetra::report
