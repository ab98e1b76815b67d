// tetra calibrate — turntable calibration: scale factor, bias and axis of every gyro with their 1σ,
// printed like seed Tables 3–5, written as a calibration file (tetra/report/calibration_report.hpp).
#include <iostream>
#include <optional>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/report/calibration_report.hpp"

namespace tetra::cli {

namespace {

struct CalibrateOptions {
  std::string input;
  std::string output;
  std::optional<double> latitude_deg;
  std::string method_name = "sixteen";
  std::string bias_model_name = "body";
  std::string compare_path;
  std::string unit_name;
  std::string noise_path;
  double correlation_s = 100.0;
};

void add_options(CLI::App& app, CalibrateOptions& o) {
  app.add_option("TURNTABLE.csv", o.input,
                 "turntable log: sequence,time_s,inner_deg,outer_deg,g1..gN (CSV, or TDMS when named .tdms)")
      ->required();
  app.add_option("-o,--output", o.output,
                 "calibration file to write (YAML, docs/interfaces.md §2.3; - for standard output)")
      ->required();
  app.add_option("--latitude", o.latitude_deg,
                 "[deg] geodetic latitude of the table (default: the file's '# latitude_deg=' comment)")
      ->check(CLI::Range(-90.0, 90.0));
  app.add_option(
         "--method", o.method_name,
         "sixteen: per-sequence means and pair differences (seed); batch: least squares over every sample")
      ->check(CLI::IsMember({"sixteen", "batch"}))
      ->capture_default_str();
  app.add_option("--bias-model", o.bias_model_name,
                 "sixteen only. body: Earth rate projected into B per sequence; seed: the seed's eq. 11 "
                 "(lab-frame Earth rate, wrong while the body is rotated)")
      ->check(CLI::IsMember({"body", "seed"}))
      ->capture_default_str();
  app.add_option(
      "--compare", o.compare_path,
      "another calibration (e.g. examples/factory.yaml): print its per-sequence residuals beside the new "
      "one's (seed Fig. 4)");
  app.add_option("--unit", o.unit_name,
                 "unit name for the calibration file (default: '# unit=' comment or tetra-1)");
  app.add_option("--noise", o.noise_path,
                 "calibration file whose gyros carry 'noise:' sections (e.g. from tetra allan "
                 "--update-calibration): bias instability and rate random walk enter the 1-sigma "
                 "(docs/calibration.md); without it the 1-sigma assume white noise");
  app.add_option("--bias-instability-correlation", o.correlation_s,
                 "[s] correlation time of the Gauss-Markov model of bias instability (with --noise)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

}  // namespace

int cmd_calibrate(int argc, char** argv) {
  CLI::App app{
      "Turntable calibration (seed eqs. 4-11): scale factor, bias and sensing axis of every gyro with their "
      "1-sigma, from a turntable log (docs/interfaces.md §2.1). Body rates come from the encoder angles.",
      "calibrate"};
  CalibrateOptions options;
  add_options(app, options);
  if (auto status = parse(app, argc, argv)) return *status;
  report::CalibrationReportOptions o;
  o.turntable_path = options.input;
  o.output_path = options.output;
  o.latitude_deg = options.latitude_deg;
  o.method = options.method_name == "batch" ? CalibrationMethod::kBatch : CalibrationMethod::kSixteen;
  o.bias_model = options.bias_model_name == "seed" ? BiasModel::kSeed : BiasModel::kBody;
  o.compare_path = options.compare_path;
  o.unit = options.unit_name;
  o.noise_path = options.noise_path;
  o.bias_instability_correlation_s = options.correlation_s;
  o.names = {{"command", "tetra calibrate"}, {"turntable_path", "TURNTABLE.csv"}, {"output_path", "--output"},
             {"latitude_deg", "--latitude"}, {"compare_path", "--compare"},       {"noise_path", "--noise"}};
  if (auto result = report::write_calibration_report(o, std::cout, std::cerr); !result) {
    return report(
        "calibrate", result.error(),
        {{"bias_model", "--bias-model applies to --method sixteen only (batch fits the bias per sample)"}});
  }
  return kExitOk;
}

}  // namespace tetra::cli
