#pragma once
// Running the open-loop simulator (the scenario's closed-form motion: static, orbit, slews, ...)
// through an attitude estimator (the fusion pipeline in process, or a service over DDS) and keeping
// what a campaign judges: the FDI events and the attitude knowledge at the end. Nothing steers: the
// estimate is only scored against the truth.

#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::sim {

struct OpenLoopRecord {
  std::vector<fdi::FdiEvent> events;
  double final_knowledge_error_deg = 0.0;  //!< [deg] last estimate vs the truth of its epoch (NaN: none)
  double final_sigma_deg = 0.0;            //!< [deg] its largest published 1σ (NaN: none)
  std::uint64_t estimates_received = 0;    //!< epochs with an estimate of that very epoch
};

//! The true attitude of epoch 0 (the estimator starts from it, as after star-tracker acquisition).
Quaternion open_loop_initial_q_RB(const Simulator& simulator);

//! Runs the simulator to its end through `estimator`.
//! `interrupt` (optional) is polled every epoch (epochs done of the run's): when it asks to stop, the
//! run returns interrupted().
Result<OpenLoopRecord> run_open_loop(Simulator& simulator, Estimator& estimator,
                                     Interrupt* interrupt = nullptr);

}  // namespace tetra::sim
