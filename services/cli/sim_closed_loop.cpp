#include "sim_closed_loop.hpp"

namespace tetra::cli {

void add_closed_loop_options(CLI::App& app, ClosedLoopCliOptions& o) {
  app.add_flag(
      "--closed-loop", o.enabled,
      "closed loop: the scenario's closed_loop section (dynamics, wheels, controller) steered by the "
      "fusion pipeline's attitude (in process, or with --dds over DDS)");
  app.add_option("--calibration", o.calibration_path,
                 "--closed-loop: calibration the pipeline uses (default: the simulated unit's own)");
  app.add_option("--config", o.config_path, "--closed-loop: YAML file with a pipeline: map (docs/fdi.md)");
  app.add_flag("--no-exclusion", o.no_exclusion, "--closed-loop: pipeline exclusion_enabled = false");
  app.add_flag("--compare-exclusion", o.compare_exclusion,
               "--closed-loop: run twice, with and without exclusion, and plot both");
  app.add_option("--pointing", o.pointing_path,
                 "--closed-loop: pointing/wheel time series CSV (docs/sim.md)");
  app.add_option("--summary", o.summary_path, "--closed-loop: JSON summary of the pointing");
  app.add_option("--plot", o.plot_path, "--closed-loop: PNG plot (needs gnuplot)");
  app.add_flag("--real-time", o.real_time,
               "--closed-loop --dds: pace on the wall clock (--speed) and steer with the newest Attitude "
               "received (default: lockstep)");
}

}  // namespace tetra::cli
