// tetra replay — the whole fusion pipeline offline: gyro log in; attitude (docs/interfaces.md §2.4) and FDI
// events (docs/interfaces.md §2.5) out; a summary on stderr (tetra/report/replay_log.hpp).
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/report/replay_log.hpp"

namespace tetra::cli {

namespace {

void add_options(CLI::App& app, report::ReplayLogOptions& o) {
  app.add_option("LOG", o.log_path, "gyro log (CSV, HDF5 when named .h5, TDMS when named .tdms)")->required();
  app.add_option("--calibration", o.calibration_path, "calibration file (YAML, docs/interfaces.md §2.3)")
      ->required();
  app.add_option("--latitude", o.latitude_deg,
                 "[deg] ground-test mode: remove the Earth rate at this geodetic latitude")
      ->check(CLI::Range(-90.0, 90.0));
  app.add_option("--initial-q", o.initial_q,
                 "initial attitude w,x,y,z (relative to the lab frame in ground mode), 1 sigma "
                 "pipeline.initial_sigma_deg; the log's first reference sample, if any, sets it instead");
  app.add_option("--config", o.config_path, "YAML file with a 'pipeline:' map of thresholds (docs/fdi.md)");
  app.add_option("--attitude", o.attitude_path, "attitude output (CSV)")->required();
  app.add_option("--events", o.events_path, "FDI events output (JSON lines)")->required();
  app.add_option("--commands", o.commands_path,
                 "operator commands to re-apply where the service obeyed them (JSON lines of tetra record "
                 "--commands)");
  // Printed while parsing, before the required options are checked: no log is needed.
  app.add_flag_callback(
      "--config-keys",
      [] {
        std::cout << fdi::describe_keys();
        throw CLI::Success();
      },
      "print every key of the 'pipeline:' map (--config): unit, range, default, meaning; then exit");
  app.add_flag_callback(
      "--config-example",
      [] {
        std::cout << fdi::example_config();
        throw CLI::Success();
      },
      "print a 'pipeline:' configuration of every key at its default (examples/fusion.yaml); then exit");
  app.add_flag("-v,--verbose", o.verbose, "echo the configuration and the derived thresholds on stderr");
  app.add_option(
      "--explain", o.explain_s,
      "[s] print the hypothesis ledger at this time of the log on stdout: the detectors' state and "
      "the last decisions before it, each with the rows that decided it (docs/fdi.md)");
}

}  // namespace

int cmd_replay(int argc, char** argv) {
  CLI::App app{
      "Run the fusion and fault-detection pipeline over a gyro log (docs/interfaces.md §2.2): writes the "
      "attitude (§2.4) and the FDI events (§2.5); prints a summary on stderr.",
      "replay"};
  report::ReplayLogOptions options;
  options.names = {{"command", "tetra replay"},
                   {"log_path", "LOG"},
                   {"calibration_path", "--calibration"},
                   {"config_path", "--config"},
                   {"commands_path", "--commands"},
                   {"attitude_path", "--attitude"},
                   {"events_path", "--events"}};
  add_options(app, options);
  if (auto status = parse(app, argc, argv)) return *status;
  options.progress_terminal = ::isatty(STDERR_FILENO) == 1 ? stderr : nullptr;
  auto replayed = report::replay_log(options, std::cerr);
  if (!replayed)
    return report("replay", replayed.error(), {{report::kSubjectInitialQ, "--initial-q: {message}"}});
  std::cout << replayed->explanation;
  return kExitOk;
}

}  // namespace tetra::cli
