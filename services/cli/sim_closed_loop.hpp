#pragma once
// `tetra sim SCENARIO.yaml --closed-loop`: the closed-loop simulation with the fusion pipeline in
// process (docs/sim.md "Closed loop"); writes the pointing series, the JSON summary and a plot.

#include <string>

#include <CLI/CLI.hpp>

#include "tetra/core/result.hpp"
#include "tetra/sim/closed_loop.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::cli {

struct ClosedLoopCliOptions {
  bool enabled = false;            //!< --closed-loop
  std::string calibration_path;    //!< --calibration: what the pipeline calibrates with (default: the unit)
  std::string config_path;         //!< --config: the `pipeline:` map
  bool no_exclusion = false;       //!< --no-exclusion: exclusion_enabled = false
  bool compare_exclusion = false;  //!< --compare-exclusion: run with and without, plot both
  std::string pointing_path;       //!< --pointing: the series CSV
  std::string summary_path;        //!< --summary: the JSON summary
  std::string plot_path;           //!< --plot: PNG
  bool real_time = false;          //!< --real-time (with --dds): latest Attitude, wall-clock pacing
};

void add_closed_loop_options(CLI::App& app, ClosedLoopCliOptions& options);

//! The scenario has a closed_loop section and the options go together.
Status check_closed_loop_options(const sim::Scenario& scenario, const ClosedLoopCliOptions& options,
                                 bool over_dds);
//! Summarizes one run, prints the summary and writes --pointing, --summary and --plot.
int write_closed_loop_outputs(const sim::Scenario& scenario, const sim::ClosedLoopSimulator& simulator,
                              const sim::ClosedLoopRecord& record, const ClosedLoopCliOptions& options);

//! Runs the loop in process and writes the outputs.
int sim_closed_loop_main(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                         const ClosedLoopCliOptions& options);

}  // namespace tetra::cli
