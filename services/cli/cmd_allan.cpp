// tetra allan — Allan deviation with confidence intervals and the IEEE 952 noise terms of a gyro log
// (tetra/report/allan_report.hpp).
#include <unistd.h>

#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/core/allan.hpp"
#include "tetra/report/allan_report.hpp"

namespace tetra::cli {

namespace {

void add_options(CLI::App& app, report::AllanReportOptions& o) {
  app.add_option("log", o.log_path,
                 "gyro log (CSV, HDF5 when named .h5, TDMS when named .tdms; docs/formats.md): "
                 "time_s,g1..gN; volts, or deg/s "
                 "with '# units=dps'")
      ->required();
  app.add_option("--calibration", o.calibration_path,
                 "calibration YAML: volts become deg/s as (g - bias)/scale");
  app.add_flag("--update-calibration", o.update_calibration,
               "write the fitted terms into the calibration file's noise: sections (needs --calibration)");
  app.add_option("--gyro", o.gyros, "analyse only this gyro (1..N); may be repeated");
  app.add_option("--taus", o.taus,
                 "averaging times: default (about 10 per decade), octave, decade, all, or a list in seconds "
                 "like 0.1,1,10");
  app.add_option("--csv", o.csv_path, "write gyro,tau_s,adev,adev_lo,adev_hi,n");
  app.add_option("--json", o.json_path, "write the noise terms as JSON (null = not observed)");
  app.add_option("--plot", o.plot_path, "write a log-log PNG plot (needs gnuplot)");
  app.add_option(
      "--kalibr", o.kalibr_path,
      "write Kalibr's imu.yaml: gyroscope noise density and random walk of the body axes, in rad/s "
      "(needs --calibration)");
  app.add_option("--confidence", o.confidence,
                 "two-sided confidence level of the intervals (default 0.683 = 1 sigma)");
  app.add_option("--dt-tolerance", o.dt_tolerance,
                 "allowed deviation of a time step from a whole multiple of the sampling interval, relative "
                 "(default 0.05)");
}

}  // namespace

int cmd_allan(int argc, char** argv) {
  CLI::App app(
      "Overlapping Allan deviation of each gyro of a log, with chi-squared confidence intervals "
      "(NIST SP 1065), and the IEEE Std 952-1997 noise terms Q, N, B, K, R fitted by non-negative "
      "weighted least squares; terms the data do not show are reported as NO (null).",
      "allan");
  report::AllanReportOptions options;
  options.names = {{"command", "tetra allan"},
                   {"log_path", "log"},
                   {"calibration_path", "--calibration"},
                   {"update_calibration", "--update-calibration"},
                   {"csv_path", "--csv"},
                   {"json_path", "--json"},
                   {"plot_path", "--plot"},
                   {"kalibr_path", "--kalibr"}};
  add_options(app, options);
  if (auto status = parse(app, argc, argv)) return *status;
  options.progress = ::isatty(STDERR_FILENO) != 0;
  if (auto r = report::write_allan_report(options, std::cout, std::cerr); !r) {
    return report("allan", r.error(),
                  {{allan::kSubjectTaus, "--taus: {message}"},
                   {allan::kSubjectGyros, "--gyro {value}: {message}"},
                   {allan::kSubjectOtherGyros, "{message} (--gyro N analyses the others alone)"},
                   {allan::kSubjectNoiseUpdate, "--update-calibration: {message}"},
                   {allan::kSubjectKalibr, "--kalibr: {message}"},
                   {"update_calibration", "--update-calibration needs --calibration CAL.yaml"},
                   {"kalibr_path", "--kalibr needs --calibration CAL.yaml (the gyro axes)"},
                   {"dt_tolerance", "--dt-tolerance {value}: {message}"},
                   {"confidence", "--confidence {value}: {message}"}});
  }
  return kExitOk;
}

}  // namespace tetra::cli
