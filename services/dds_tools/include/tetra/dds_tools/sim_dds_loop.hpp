#pragma once
// The closed loop over DDS (`tetra sim SCENARIO.yaml --closed-loop --dds`, docs/sim.md "Closed loop over
// DDS"), with a running `tetra fusion` service as the estimator:
//   lockstep (default)  publish epoch k's samples, wait for epoch k's Attitude, control, integrate
//                       to k+1: as fast as the loop allows, and the same numbers as in process
//   real time           publish at the wall-clock rate (speed); the controller uses the newest
//                       Attitude received, however old (latency and losses are the experiment)

#include <cstdint>

#include "tetra/core/result.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds_tools/sim_dds.hpp"
#include "tetra/sim/closed_loop.hpp"
#include "tetra/sim/closed_loop_run.hpp"

namespace tetra::dds_tools {

struct DdsClosedLoopRun {
  sim::ClosedLoopRecord record;  //!< fdi_events false: the service's FdiEvent topic is not read
  std::uint64_t missing = 0;     //!< lockstep epochs without their Attitude within the lockstep timeout
};

//! Runs `simulator` (of its scenario) to its end or the shutdown, steered by the service's Attitude.
Result<DdsClosedLoopRun> run_closed_loop_dds(sim::ClosedLoopSimulator& simulator, bool real_time,
                                             const SimDdsOptions& options,
                                             const dds::ShutdownSignal& shutdown);

}  // namespace tetra::dds_tools
