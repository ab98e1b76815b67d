#include "tetra/sim/requirement.hpp"

#include <cmath>
#include <optional>
#include <sstream>

#include "tetra/core/csv.hpp"
#include "tetra/sim/fault.hpp"

namespace tetra::sim {

namespace {

constexpr RequirementMetric kMetrics[] = {
    RequirementMetric::kRightRate,          RequirementMetric::kWrongRate,
    RequirementMetric::kUnisolatedRate,     RequirementMetric::kMissedRate,
    RequirementMetric::kDetectionRate,      RequirementMetric::kIsolationRate,
    RequirementMetric::kWrongExclusionRate, RequirementMetric::kFalseAlarmsPerHour};

//! A finite decimal number written whole in `text` (no hexadecimal, as everywhere else), or nullopt.
std::optional<double> number_in(const std::string& text) {
  return parse_decimal(text);
}

std::string metric_list() {
  std::string out;
  for (RequirementMetric m : kMetrics) out += (out.empty() ? "" : ", ") + requirement_metric_name(m);
  return out;
}

}  // namespace

std::string requirement_metric_name(RequirementMetric metric) {
  switch (metric) {
    case RequirementMetric::kRightRate:
      return "right_rate";
    case RequirementMetric::kWrongRate:
      return "wrong_rate";
    case RequirementMetric::kUnisolatedRate:
      return "unisolated_rate";
    case RequirementMetric::kMissedRate:
      return "missed_rate";
    case RequirementMetric::kDetectionRate:
      return "detection_rate";
    case RequirementMetric::kIsolationRate:
      return "isolation_rate";
    case RequirementMetric::kWrongExclusionRate:
      return "wrong_exclusion_rate";
    case RequirementMetric::kFalseAlarmsPerHour:
      return "false_alarms_per_hour";
  }
  return "?";
}

Result<Requirement> parse_requirement(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  const std::string form =
      "expected 'METRIC < BOUND at CONFIDENCE' (or >), e.g. 'wrong_exclusion_rate < 1e-3 at 0.95'";
  if (words.size() != 5 || words[3] != "at" || (words[1] != "<" && words[1] != ">")) return bad_input(form);
  Requirement r;
  r.text = text;
  std::string metric = words[0];
  if (const auto open = metric.find('['); open != std::string::npos) {
    if (metric.back() != ']') return bad_input("'" + metric + "': expected METRIC[KIND]");
    r.kind = metric.substr(open + 1, metric.size() - open - 2);
    metric = metric.substr(0, open);
    if (r.kind != "none" && !fault_kind_from_name(r.kind))
      return bad_input("'" + r.kind + "' is not a fault kind (or none)");
  }
  bool known = false;
  for (RequirementMetric m : kMetrics) {
    if (requirement_metric_name(m) == metric) {
      r.metric = m;
      known = true;
    }
  }
  if (!known) return bad_input("'" + metric + "' is not a metric (" + metric_list() + ")");
  const bool over_faulty = r.metric != RequirementMetric::kWrongExclusionRate &&
                           r.metric != RequirementMetric::kFalseAlarmsPerHour;
  if (over_faulty && r.kind == "none")
    return bad_input(metric + " counts faulty runs: [none] selects none of them");
  r.below = words[1] == "<";
  const auto bound = number_in(words[2]);
  const auto confidence = number_in(words[4]);
  if (!bound) return bad_input("bound '" + words[2] + "' is not a number");
  if (!confidence || *confidence <= 0.0 || *confidence >= 1.0)
    return bad_input("confidence '" + words[4] + "' must be a number in (0, 1)");
  r.bound = *bound;
  r.confidence = *confidence;
  if (r.metric == RequirementMetric::kFalseAlarmsPerHour) {
    if (r.bound <= 0.0) return bad_input("a false-alarm frequency bound must be positive");
  } else if (r.below ? !(r.bound > 0.0 && r.bound <= 1.0) : !(r.bound >= 0.0 && r.bound < 1.0)) {
    return bad_input(std::string("a rate bound must lie in ") + (r.below ? "(0, 1] for <" : "[0, 1) for >") +
                     " (no campaign can show otherwise)");
  }
  return r;
}

}  // namespace tetra::sim
