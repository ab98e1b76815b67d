#include "tetra/sim/fdi_verdict.hpp"

#include "tetra/core/units.hpp"

namespace tetra::sim {

std::string_view outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::kNone:
      return "none";
    case Outcome::kRight:
      return "right";
    case Outcome::kWrong:
      return "wrong";
    case Outcome::kUnisolated:
      return "unisolated";
    case Outcome::kMissed:
      return "missed";
  }
  return "?";
}

FdiVerdict judge_fdi(const std::vector<fdi::FdiEvent>& events, const std::vector<FaultSpec>& faults,
                     double duration_s) {
  FdiVerdict v;
  const FaultSpec* fault = faults.empty() ? nullptr : &faults.front();
  const double onset_s = fault ? fault->at_s : duration_s;
  v.fault_free_s = std::min(onset_s, duration_s);
  for (const fdi::FdiEvent& e : events) {
    const double t = ns_to_seconds(e.stamp_ns);
    if (e.type == fdi::EventType::kDetected) {
      if (t < onset_s) {
        ++v.false_alarms;
      } else if (!v.detection_delay_s) {
        v.detection_delay_s = t - onset_s;
      }
    } else if (e.type == fdi::EventType::kIsolated && e.gyro) {
      if ((!fault || *e.gyro != fault->gyro) && !v.wrong_gyro) {
        v.wrong_gyro = *e.gyro;
        v.wrong_at_s = t;
      }
      if (t >= onset_s && !v.isolation_delay_s) {
        v.isolation_delay_s = t - onset_s;
        v.isolated_gyro = *e.gyro;
      }
    }
  }
  if (v.wrong_gyro) {
    v.outcome = Outcome::kWrong;
  } else if (!fault) {
    v.outcome = Outcome::kNone;
  } else if (v.isolated_gyro) {
    v.outcome = Outcome::kRight;
  } else {
    v.outcome = v.detection_delay_s ? Outcome::kUnisolated : Outcome::kMissed;
  }
  return v;
}

}  // namespace tetra::sim
