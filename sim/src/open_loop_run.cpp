#include "tetra/sim/open_loop_run.hpp"

#include <limits>

#include "tetra/core/units.hpp"

namespace tetra::sim {

Quaternion open_loop_initial_q_RB(const Simulator& simulator) {
  return simulator.motion().at(0.0).q_RB;
}

Result<OpenLoopRecord> run_open_loop(Simulator& simulator, Estimator& estimator, Interrupt* interrupt) {
  constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
  OpenLoopRecord record;
  record.final_knowledge_error_deg = kUnknown;
  record.final_sigma_deg = kUnknown;
  SimEpoch epoch;
  while (simulator.next(epoch)) {
    if (interrupt_requested(interrupt, simulator.epochs_done(), simulator.epoch_count()))
      return interrupted();
    auto out = estimator.estimate(epoch);
    if (!out) return out.error();
    record.events.insert(record.events.end(), out->events.begin(), out->events.end());
    if (!out->latest || out->latest->stamp_ns != epoch.stamp_ns) continue;
    ++record.estimates_received;
    record.final_knowledge_error_deg = angle_between(out->latest->q_RB, epoch.truth_q_RB) * kRadToDeg;
    record.final_sigma_deg = out->latest->sigma_rad.maxCoeff() * kRadToDeg;
  }
  if (Status st = estimator.finish(record.events); !st) return st.error();
  return record;
}

}  // namespace tetra::sim
