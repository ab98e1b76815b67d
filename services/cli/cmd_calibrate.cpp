// tetra calibrate — turntable calibration: scale factor, bias and axis of every gyro with their 1σ,
// printed like seed Tables 3–5, written as a calibration file (docs/interfaces.md §2.3).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/core/calibration.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/turntable_rows.hpp"
#include "tetra/core/units.hpp"

namespace tetra::cli {

namespace {

constexpr const char* kCalibrateName = "calibrate";

template <class... Args>
std::string format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

Result<double> latitude_from(const TurntableRows& log, const std::optional<double>& option_deg) {
  if (option_deg) return *option_deg;
  const auto text = log.meta("latitude_deg");
  if (!text) {
    return bad_input(log.source() +
                     ": no latitude: give --latitude DEG or a '# latitude_deg=DEG' comment line in the file");
  }
  const auto v = parse_decimal(*text);
  if (!v) return bad_input(log.source() + ": comment '# latitude_deg=" + *text + "' is not a decimal number");
  if (std::abs(*v) > 90.0)
    return bad_input(log.source() + ": comment '# latitude_deg=" + *text + "' is outside [-90, 90] deg");
  return *v;
}

void print_plan(const TurntableRows& log, const TurntableMotion& motion) {
  std::cout
      << "Rotation plan derived from the encoders (cf. seed Table 3; body rate = table + Earth, mean)\n";
  std::cout << " seq  lines          gimbal   rate[deg/s]  turned[deg]  other gimbal[deg]"
               "   omega_B x[deg/s]    y[deg/s]    z[deg/s]\n";
  for (const auto& m : motion.sequences) {
    const Eigen::Vector3d w = m.rate_B_dps();
    const std::string lines = std::to_string(m.first_line) + "-" + std::to_string(m.last_line);
    std::cout << format(" %3d  %-13s  %-6s  %+11.5f  %+11.3f  %s %+9.4f   %+12.6f  %+10.6f  %+10.6f\n",
                        m.sequence, lines.c_str(), to_string(m.rotating), m.rate_dps, m.turned_deg,
                        m.rotating == Gimbal::kInner ? "outer" : "inner", m.fixed_angle_deg, w.x(), w.y(),
                        w.z());
  }
  std::cout << format("(%zu rows, %d gyros, latitude %+.4f deg)\n\n", log.rows(), log.gyro_count(),
                      motion.latitude_deg);
}

void print_estimates(const CalibrationResult& result, const CalibrationOptions& options,
                     const std::optional<Calibration>& reference, const std::string& reference_name) {
  const Calibration& cal = result.calibration;
  std::cout << "Scale factors and biases (cf. seed Table 4), method " << to_string(options.method);
  if (options.method == CalibrationMethod::kSixteen)
    std::cout << ", bias model " << to_string(options.bias_model);
  std::cout << "\n";
  std::cout << " gyro  scale[V/(deg/s)]    1-sigma";
  if (reference) std::cout << "  diff wrt ref";
  std::cout << "      bias[V]    1-sigma";
  if (reference) std::cout << "  diff wrt ref";
  std::cout << "   resid RMS[V]: samples  seq.means\n";
  for (int i = 0; i < cal.gyro_count(); ++i) {
    const auto& g = cal.gyros[static_cast<std::size_t>(i)];
    std::cout << format(" %4d  %16.8f  %9.2e", g.id, g.scale_factor_V_per_dps,
                        g.sigma->scale_factor_V_per_dps);
    if (reference) {
      std::cout << format(
          "  %+12.6f",
          g.scale_factor_V_per_dps - reference->gyros[static_cast<std::size_t>(i)].scale_factor_V_per_dps);
    }
    std::cout << format("  %+11.8f  %9.2e", g.bias_V, g.sigma->bias_V);
    if (reference)
      std::cout << format("  %+12.6f", g.bias_V - reference->gyros[static_cast<std::size_t>(i)].bias_V);
    std::cout << format("   %20.3e  %9.3e\n", result.fit.sample_rms_V(i), result.fit.sequence_rms_V(i));
  }
  std::cout << "\n";

  std::cout << "Sensing axes H~ in B, unit vectors (cf. seed Table 5)\n";
  std::cout << " gyro           x            y            z      1-sigma x    1-sigma y    1-sigma z";
  if (reference) std::cout << "   angle to ref[deg]";
  std::cout << "\n";
  for (int i = 0; i < cal.gyro_count(); ++i) {
    const auto& g = cal.gyros[static_cast<std::size_t>(i)];
    std::cout << format(" %4d  %+11.7f  %+11.7f  %+11.7f  %11.2e  %11.2e  %11.2e", g.id, g.axis_B.x(),
                        g.axis_B.y(), g.axis_B.z(), g.sigma->axis.x(), g.sigma->axis.y(), g.sigma->axis.z());
    if (reference) {
      const Eigen::Vector3d& h_ref = reference->gyros[static_cast<std::size_t>(i)].axis_B;
      const double angle_deg = std::atan2(g.axis_B.cross(h_ref).norm(), g.axis_B.dot(h_ref)) * kRadToDeg;
      std::cout << format("   %17.4f", angle_deg);
    }
    std::cout << "\n";
  }
  if (reference) {
    std::cout << " " << reference_name << " axes:\n";
    for (const auto& g : reference->gyros) {
      std::cout << format(" %4d  %+11.7f  %+11.7f  %+11.7f\n", g.id, g.axis_B.x(), g.axis_B.y(),
                          g.axis_B.z());
    }
  } else if (cal.gyro_count() == 4) {
    const auto nominal = nominal_tetrahedron_axes();
    std::cout << " nominal tetrahedron:\n";
    for (int i = 0; i < 4; ++i) {
      std::cout << format(" %4d  %+11.7f  %+11.7f  %+11.7f\n", i + 1, nominal(i, 0), nominal(i, 1),
                          nominal(i, 2));
    }
  }
  std::cout << "\n";
}

void print_comparison(const TurntableMotion& motion, const CalibrationFit& reference_fit,
                      const CalibrationFit& fit, const std::string& reference_name, int gyro_count) {
  std::cout << "Mean residual per sequence [V], measured - predicted (cf. seed Fig. 4): '" << reference_name
            << "' | new\n";
  std::cout << " seq";
  for (int i = 1; i <= gyro_count; ++i) std::cout << format("     g%d ref        g%d new  ", i, i);
  std::cout << "\n";
  for (std::size_t j = 0; j < motion.sequences.size(); ++j) {
    std::cout << format(" %3d", motion.sequences[j].sequence);
    for (int i = 0; i < gyro_count; ++i) {
      const auto row = static_cast<Eigen::Index>(j);
      std::cout << format("  %+10.3e  %+10.3e ", reference_fit.sequence_residual_V(row, i),
                          fit.sequence_residual_V(row, i));
    }
    std::cout << "\n";
  }
  std::cout << " RMS";
  for (int i = 0; i < gyro_count; ++i) {
    std::cout << format("  %10.3e  %10.3e ", reference_fit.sequence_rms_V(i), fit.sequence_rms_V(i));
  }
  std::cout << "\n ratio ref/new:";
  for (int i = 0; i < gyro_count; ++i) {
    std::cout << format("  g%d %.3g", i + 1, reference_fit.sequence_rms_V(i) / fit.sequence_rms_V(i));
  }
  std::cout << "\n\n";
}

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
  app.add_option("TURNTABLE.csv", o.input, "turntable log: sequence,time_s,inner_deg,outer_deg,g1..gN (CSV, or TDMS when named .tdms)")
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

Result<CalibrationOptions> estimator_options(const CalibrateOptions& o) {
  CalibrationOptions options;
  options.method = o.method_name == "batch" ? CalibrationMethod::kBatch : CalibrationMethod::kSixteen;
  options.bias_model = o.bias_model_name == "seed" ? BiasModel::kSeed : BiasModel::kBody;
  if (options.method == CalibrationMethod::kBatch && o.bias_model_name != "body") {
    return bad_input("--bias-model applies to --method sixteen only (batch fits the bias per sample)");
  }
  return options;
}

// The latitude (option or comment; a note on stderr when the option overrides the file's).
Result<double> latitude_of(const TurntableRows& log, const CalibrateOptions& o) {
  auto latitude = latitude_from(log, o.latitude_deg);
  if (!latitude) return latitude;
  if (o.latitude_deg) {
    if (const auto in_file = log.meta("latitude_deg")) {
      std::cerr << "tetra calibrate: using --latitude " << *o.latitude_deg << " (the file says " << *in_file
                << ")\n";
    }
  }
  return latitude;
}

// --compare: the other calibration, with as many gyros as the log.
Result<std::optional<Calibration>> reference_of(const TurntableRows& log, const CalibrateOptions& o) {
  if (o.compare_path.empty()) return std::optional<Calibration>{};
  auto ref = read_calibration(o.compare_path);
  if (!ref) return ref.error();
  if (ref->gyro_count() != log.gyro_count()) {
    return bad_input(o.compare_path + ": has " + std::to_string(ref->gyro_count()) + " gyros, " + o.input +
                     " has " + std::to_string(log.gyro_count()));
  }
  return std::optional<Calibration>(std::move(ref.value()));
}

// --noise: one noise section per gyro of the log, from another calibration file.
Status noise_model_of(const TurntableRows& log, const CalibrateOptions& o, CalibrationOptions& options) {
  if (o.noise_path.empty()) return ok_status();
  auto cal = read_calibration(o.noise_path);
  if (!cal) return cal.error();
  if (cal->gyro_count() != log.gyro_count()) {
    return bad_input(o.noise_path + ": has " + std::to_string(cal->gyro_count()) + " gyros, " + o.input +
                     " has " + std::to_string(log.gyro_count()));
  }
  options.noise.clear();
  for (const auto& g : cal->gyros) {
    if (!g.noise)
      return bad_input(o.noise_path + ": gyro " + std::to_string(g.id) + " has no 'noise:' section");
    options.noise.push_back(*g.noise);
  }
  options.bias_instability_correlation_s = o.correlation_s;
  return ok_status();
}

// With the seed's eq. 11 bias: how far it lies from the body-model bias.
void print_seed_bias_difference(const TurntableRows& log, const TurntableMotion& motion,
                                const CalibrationOptions& options, const CalibrationResult& result) {
  CalibrationOptions body = options;
  body.bias_model = BiasModel::kBody;
  auto body_result = calibrate(log, motion, body);
  if (!body_result) return;
  std::cout << "Seed eq. 11 bias minus body-model bias [V]:";
  for (int i = 0; i < log.gyro_count(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    std::cout << format("  g%d %+.3e", i + 1,
                        result.calibration.gyros[k].bias_V - body_result->calibration.gyros[k].bias_V);
  }
  std::cout << "\n(eq. 11 subtracts the lab-frame Earth rate although the body is rotated; see "
               "docs/calibration.md)\n\n";
}

// The tables on standard output: plan, estimates, the comparison, the seed-bias note, what 1σ means.
Status print_report(const TurntableRows& log, const TurntableMotion& motion,
                    const CalibrationOptions& options, const CalibrationResult& result,
                    const std::optional<Calibration>& reference, const std::string& reference_name) {
  print_plan(log, motion);
  print_estimates(result, options, reference, reference_name);
  if (reference) {
    auto reference_fit = evaluate_calibration(log, motion, *reference);
    if (!reference_fit) return reference_fit.error();
    print_comparison(motion, *reference_fit, result.fit, reference_name, log.gyro_count());
  }
  if (options.method == CalibrationMethod::kSixteen && options.bias_model == BiasModel::kSeed)
    print_seed_bias_difference(log, motion, options, result);
  std::cout << "1-sigma: "
            << (options.method == CalibrationMethod::kSixteen
                    ? "per-sequence standard deviation of the mean, propagated"
                    : "residual covariance of the fit");
  if (options.noise.empty()) {
    std::cout << "; white noise within a sequence assumed, so correlated noise (bias instability, rate "
                 "random walk) makes them optimistic (--noise adds it).\n";
  } else {
    std::cout << ", plus the covariance of the sequence means from the gyros' bias instability and rate "
                 "random walk (--noise).\n";
  }
  return ok_status();
}

// Outputs opened, log read and interpreted, calibration estimated; report; file written and committed.
Status run_calibrate(const CalibrateOptions& o) {
  auto options = estimator_options(o);
  if (!options) return options.error();
  RunFiles files;
  files.add_input(o.input, "TURNTABLE.csv");
  if (!o.compare_path.empty()) files.add_input(o.compare_path, "--compare");
  if (!o.noise_path.empty()) files.add_input(o.noise_path, "--noise");
  auto out = files.add(o.output, "--output");
  if (!out) return out.error();
  auto log = std::make_unique<TurntableFileRows>();  // the rows are read again at each pass, never held
  if (Status s = log->open(o.input); !s) return s;
  auto latitude = latitude_of(*log, o);
  if (!latitude) return latitude.error();
  options->unit = !o.unit_name.empty() ? o.unit_name : log->meta("unit").value_or("tetra-1");
  auto reference = reference_of(*log, o);
  if (!reference) return reference.error();
  if (Status s = noise_model_of(*log, o, *options); !s) return s;
  auto motion = analyze_turntable(*log, *latitude);
  if (!motion) return motion.error();
  auto result = calibrate(*log, *motion, *options);
  if (!result) return result.error();
  if (Status s = print_report(*log, *motion, *options, *result, *reference, o.compare_path); !s) return s;
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status s = write_calibration(**out, result->calibration, meta); !s) return s;
  if (Status s = files.commit(); !s) return s;
  std::cerr << "tetra calibrate: wrote " << o.output << "\n";
  return ok_status();
}

}  // namespace

int cmd_calibrate(int argc, char** argv) {
  CLI::App app{
      "Turntable calibration (seed eqs. 4-11): scale factor, bias and sensing axis of every gyro with their "
      "1-sigma, from a turntable log (docs/interfaces.md §2.1). Body rates come from the encoder angles.",
      kCalibrateName};
  CalibrateOptions options;
  add_options(app, options);
  if (auto status = parse(app, argc, argv)) return *status;
  if (Status s = run_calibrate(options); !s) return report(kCalibrateName, s.error());
  return kExitOk;
}

}  // namespace tetra::cli
