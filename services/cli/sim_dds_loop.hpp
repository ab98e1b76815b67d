#pragma once
// `tetra sim SCENARIO.yaml --closed-loop --dds`: the closed loop over DDS, with a running
// `tetra fusion` service as the estimator (docs/sim.md "Closed loop over DDS").
//   lockstep (default)  publish epoch k's samples, wait for epoch k's Attitude, control, integrate
//                       to k+1: as fast as the loop allows, and the same numbers as in process
//   --real-time         publish at the wall-clock rate (--speed); the controller uses the newest
//                       Attitude received, however old (latency and losses are the experiment)

#include "sim_closed_loop.hpp"
#include "sim_dds.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::cli {

int sim_dds_closed_loop_main(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                             const ClosedLoopCliOptions& loop_options, const SimDdsOptions& dds_options);

}  // namespace tetra::cli
