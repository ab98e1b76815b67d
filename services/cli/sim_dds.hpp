#pragma once
// `tetra sim --dds`: its options and its printed score (the run: tetra/dds_tools/sim_dds.hpp).

#include <CLI/CLI.hpp>

#include "tetra/dds_tools/sim_dds.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::cli {

using dds_tools::run_sim_dds;
using dds_tools::ScoredEpoch;
using dds_tools::SimDdsOptions;
using dds_tools::SimDdsScore;

struct SimDdsCliOptions : SimDdsOptions {
  bool enabled = false;  //!< --dds given
  bool quiet = false;    //!< no progress lines on stderr
};

//! Adds --dds, --speed, --domain, --dds-unit, --wait-readers, --wait-timeout to `tetra sim`.
void add_sim_dds_options(CLI::App& app, SimDdsCliOptions& options);

//! The `tetra sim --dds` command body after the scenario is built: runs, prints the score.
int sim_dds_main(sim::Simulator& simulator, const SimDdsCliOptions& options);

}  // namespace tetra::cli
