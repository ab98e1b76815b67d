#pragma once
// A campaign's statistics with confidence (docs/campaign.md, "Statistics"): each outcome's rate with its
// Clopper–Pearson interval, detection and isolation probability against fault size per kind (binned,
// with intervals), false alarms per hour with the Garwood interval, and each requirement judged pass /
// fail / not yet decidable with the runs still needed.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tetra/sim/campaign.hpp"
#include "tetra/sim/campaign_report.hpp"

namespace tetra::sim {

//! [-] the confidence of the report's two-sided intervals.
inline constexpr double kReportConfidence = 0.95;

enum class Verdict { kPass, kFail, kUndecided };

struct RequirementJudgement {
  Verdict verdict = Verdict::kUndecided;
  std::uint64_t events = 0;  //!< runs with the event (false alarms: detections)
  double trials = 0.0;       //!< runs (false alarms: hours of fault-free flight)
  double estimate = 0.0;     //!< events / trials (NaN without trials)
  double lower = 0.0;        //!< one-sided bounds at the requirement's confidence
  double upper = 0.0;
  //! [runs] further runs that could decide it (`<`: none with an event; `>`: each with one); nullopt when
  //! decided, or beyond reach.
  std::optional<std::uint64_t> further_runs;
};

RequirementJudgement judge_requirement(const Requirement& requirement, const std::vector<CampaignRow>& rows);

//! The statistics sections of report.md and their plots (appended to `report`).
void add_statistics(const std::vector<CampaignRow>& rows, CampaignReport& report);
//! The requirements section of report.md.
std::string requirements_section(const std::vector<Requirement>& requirements,
                                 const std::vector<CampaignRow>& rows);

}  // namespace tetra::sim
