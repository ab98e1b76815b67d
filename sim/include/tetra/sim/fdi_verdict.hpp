#pragma once
// The verdict on one run's fault detection and isolation, against the fault that was injected:
//   right       the first isolation at or after the onset names the faulty gyro (and none before)
//   wrong       a healthy gyro was isolated (at any time)
//   unisolated  detected, never isolated
//   missed      neither detected nor isolated
//   none        no fault injected and no isolation
// Delays are measured from the onset of the first fault; detections before it are false alarms.

#include <optional>
#include <string_view>
#include <vector>

#include "tetra/fdi/types.hpp"
#include "tetra/sim/fault.hpp"

namespace tetra::sim {

enum class Outcome { kNone, kRight, kWrong, kUnisolated, kMissed };
std::string_view outcome_name(Outcome outcome);

struct FdiVerdict {
  Outcome outcome = Outcome::kNone;
  std::optional<double> detection_delay_s;  //!< [s] first detection at or after the onset
  std::optional<double> isolation_delay_s;  //!< [s] first isolation at or after the onset
  std::optional<int> isolated_gyro;         //!< 1..N: the gyro of the first isolation
  std::optional<int> wrong_gyro;            //!< 1..N: the first healthy gyro isolated
  std::optional<double> wrong_at_s;         //!< [s] when
  int false_alarms = 0;                     //!< detections before the onset (all, without a fault)
  double fault_free_s = 0.0;                //!< [s] time before the onset (the run without a fault)
};

//! `duration_s`: the run's length; `faults`: the injected faults (the first one is judged).
FdiVerdict judge_fdi(const std::vector<fdi::FdiEvent>& events, const std::vector<FaultSpec>& faults,
                     double duration_s);

}  // namespace tetra::sim
