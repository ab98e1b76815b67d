#pragma once
// A campaign's requirements (the spec's `requirements:` list, docs/campaign.md "Requirements"): a rate or
// a false-alarm frequency bounded at a confidence, e.g. `wrong_exclusion_rate < 1e-3 at 0.95`, judged by
// the report (tetra/sim/campaign_statistics.hpp).

#include <string>
#include <vector>

#include "tetra/core/result.hpp"

namespace tetra::sim {

enum class RequirementMetric {
  kRightRate,           //!< right_rate: faulty runs with outcome right
  kWrongRate,           //!< wrong_rate: faulty runs with outcome wrong
  kUnisolatedRate,      //!< unisolated_rate
  kMissedRate,          //!< missed_rate
  kDetectionRate,       //!< detection_rate: faulty runs with a detection at or after the onset
  kIsolationRate,       //!< isolation_rate: faulty runs whose first isolation names the faulty gyro
  kWrongExclusionRate,  //!< wrong_exclusion_rate: runs (fault-free included) excluding a healthy gyro
  kFalseAlarmsPerHour,  //!< false_alarms_per_hour: detections before the onset per hour of such flight
};

struct Requirement {
  std::string text;  //!< as written
  RequirementMetric metric = RequirementMetric::kWrongExclusionRate;
  std::string kind;         //!< `metric[kind]`: only runs of this kind ("none": fault-free); "" all
  bool below = true;        //!< `<` (true) or `>`
  double bound = 0.0;       //!< [-] a rate, or [1/h] for false_alarms_per_hour
  double confidence = 0.0;  //!< in (0, 1)
};

//! "METRIC[KIND] < BOUND at CONFIDENCE" (or `>`); the error says what is wrong (the caller adds where).
Result<Requirement> parse_requirement(const std::string& text);
std::string requirement_metric_name(RequirementMetric metric);

}  // namespace tetra::sim
