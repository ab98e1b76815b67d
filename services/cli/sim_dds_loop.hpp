#pragma once
// `tetra sim SCENARIO.yaml --closed-loop --dds`: runs the closed loop over DDS
// (tetra/dds_tools/sim_dds_loop.hpp) and prints and writes its outputs (tetra/report/closed_loop_files.hpp).

#include "sim_closed_loop.hpp"
#include "sim_dds.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::cli {

int sim_dds_closed_loop_main(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                             const ClosedLoopCliOptions& loop_options, const SimDdsOptions& dds_options);

}  // namespace tetra::cli
