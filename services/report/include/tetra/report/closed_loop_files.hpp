#pragma once
// The closed-loop simulation with the fusion pipeline in process (`tetra sim SCENARIO --closed-loop`,
// docs/sim.md "Closed loop"): runs it, prints the pointing summary on a given stream and writes the
// pointing series, the JSON summary and a plot. A plot's error carries kPlotSubject.

#include <ostream>
#include <string>

#include "tetra/core/result.hpp"
#include "tetra/sim/closed_loop.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::report {

struct ClosedLoopOptions {
  std::string calibration_path;    //!< what the pipeline calibrates with (empty: the simulated unit)
  std::string config_path;         //!< YAML file with the `pipeline:` map (empty: defaults)
  bool no_exclusion = false;       //!< exclusion_enabled = false
  bool compare_exclusion = false;  //!< run with and without exclusion, plot both
  std::string pointing_path;       //!< the series CSV (empty: none)
  std::string summary_path;        //!< the JSON summary (empty: none)
  std::string plot_path;           //!< PNG (empty: none)
  bool real_time = false;          //!< over DDS: latest Attitude, wall-clock pacing
};

//! The scenario has a closed_loop section and the options go together (`over_dds`: the estimator is a
//! service, configured by itself).
Status check_closed_loop_options(const sim::Scenario& scenario, const ClosedLoopOptions& options,
                                 bool over_dds);
//! Summarizes one run, prints the summary on `out` and writes the pointing series, summary and plot.
Status write_closed_loop_outputs(const sim::Scenario& scenario, const sim::ClosedLoopSimulator& simulator,
                                 const sim::ClosedLoopRecord& record, const ClosedLoopOptions& options,
                                 std::ostream& out);
//! Runs the loop in process (twice with compare_exclusion), prints the summaries on `out`, writes the
//! outputs.
Status run_closed_loop_to_files(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                                const ClosedLoopOptions& options, std::ostream& out);

}  // namespace tetra::report
