// The calibration report of `tetra calibrate` (tetra/report/calibration_report.hpp).
#include "tetra/report/calibration_report.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/turntable_rows.hpp"
#include "tetra/core/units.hpp"

namespace tetra::report {

namespace {

template <class... Args>
std::string cal_format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

Result<double> latitude_from(const TurntableRows& log, const std::optional<double>& option_deg,
                             const std::string& option_name) {
  if (option_deg) return *option_deg;
  const auto text = log.meta("latitude_deg");
  if (!text) {
    return bad_input(log.source() + ": no latitude: give " + option_name +
                     " DEG or a '# latitude_deg=DEG' comment line in the file");
  }
  const auto v = parse_decimal(*text);
  if (!v) return bad_input(log.source() + ": comment '# latitude_deg=" + *text + "' is not a decimal number");
  if (std::abs(*v) > 90.0)
    return bad_input(log.source() + ": comment '# latitude_deg=" + *text + "' is outside [-90, 90] deg");
  return *v;
}

void print_plan(std::ostream& out, const TurntableRows& log, const TurntableMotion& motion) {
  out << "Rotation plan derived from the encoders (cf. seed Table 3; body rate = table + Earth, mean)\n";
  out << " seq  lines          gimbal   rate[deg/s]  turned[deg]  other gimbal[deg]"
         "   omega_B x[deg/s]    y[deg/s]    z[deg/s]\n";
  for (const auto& m : motion.sequences) {
    const Eigen::Vector3d w = m.rate_B_dps();
    const std::string lines = std::to_string(m.first_line) + "-" + std::to_string(m.last_line);
    out << cal_format(" %3d  %-13s  %-6s  %+11.5f  %+11.3f  %s %+9.4f   %+12.6f  %+10.6f  %+10.6f\n",
                      m.sequence, lines.c_str(), to_string(m.rotating), m.rate_dps, m.turned_deg,
                      m.rotating == Gimbal::kInner ? "outer" : "inner", m.fixed_angle_deg, w.x(), w.y(),
                      w.z());
  }
  out << cal_format("(%zu rows, %d gyros, latitude %+.4f deg)\n\n", log.rows(), log.gyro_count(),
                    motion.latitude_deg);
}

void print_estimates(std::ostream& out, const CalibrationResult& result, const CalibrationOptions& options,
                     const std::optional<Calibration>& reference, const std::string& reference_name) {
  const Calibration& cal = result.calibration;
  out << "Scale factors and biases (cf. seed Table 4), method " << to_string(options.method);
  if (options.method == CalibrationMethod::kSixteen) out << ", bias model " << to_string(options.bias_model);
  out << "\n";
  out << " gyro  scale[V/(deg/s)]    1-sigma";
  if (reference) out << "  diff wrt ref";
  out << "      bias[V]    1-sigma";
  if (reference) out << "  diff wrt ref";
  out << "   resid RMS[V]: samples  seq.means\n";
  for (int i = 0; i < cal.gyro_count(); ++i) {
    const auto& g = cal.gyros[static_cast<std::size_t>(i)];
    out << cal_format(" %4d  %16.8f  %9.2e", g.id, g.scale_factor_V_per_dps, g.sigma->scale_factor_V_per_dps);
    if (reference) {
      out << cal_format(
          "  %+12.6f",
          g.scale_factor_V_per_dps - reference->gyros[static_cast<std::size_t>(i)].scale_factor_V_per_dps);
    }
    out << cal_format("  %+11.8f  %9.2e", g.bias_V, g.sigma->bias_V);
    if (reference)
      out << cal_format("  %+12.6f", g.bias_V - reference->gyros[static_cast<std::size_t>(i)].bias_V);
    out << cal_format("   %20.3e  %9.3e\n", result.fit.sample_rms_V(i), result.fit.sequence_rms_V(i));
  }
  out << "\n";

  out << "Sensing axes H~ in B, unit vectors (cf. seed Table 5)\n";
  out << " gyro           x            y            z      1-sigma x    1-sigma y    1-sigma z";
  if (reference) out << "   angle to ref[deg]";
  out << "\n";
  for (int i = 0; i < cal.gyro_count(); ++i) {
    const auto& g = cal.gyros[static_cast<std::size_t>(i)];
    out << cal_format(" %4d  %+11.7f  %+11.7f  %+11.7f  %11.2e  %11.2e  %11.2e", g.id, g.axis_B.x(),
                      g.axis_B.y(), g.axis_B.z(), g.sigma->axis.x(), g.sigma->axis.y(), g.sigma->axis.z());
    if (reference) {
      const Eigen::Vector3d& h_ref = reference->gyros[static_cast<std::size_t>(i)].axis_B;
      const double angle_deg = std::atan2(g.axis_B.cross(h_ref).norm(), g.axis_B.dot(h_ref)) * kRadToDeg;
      out << cal_format("   %17.4f", angle_deg);
    }
    out << "\n";
  }
  if (reference) {
    out << " " << reference_name << " axes:\n";
    for (const auto& g : reference->gyros) {
      out << cal_format(" %4d  %+11.7f  %+11.7f  %+11.7f\n", g.id, g.axis_B.x(), g.axis_B.y(), g.axis_B.z());
    }
  } else if (cal.gyro_count() == 4) {
    const auto nominal = nominal_tetrahedron_axes();
    out << " nominal tetrahedron:\n";
    for (int i = 0; i < 4; ++i) {
      out << cal_format(" %4d  %+11.7f  %+11.7f  %+11.7f\n", i + 1, nominal(i, 0), nominal(i, 1),
                        nominal(i, 2));
    }
  }
  out << "\n";
}

void print_comparison(std::ostream& out, const TurntableMotion& motion, const CalibrationFit& reference_fit,
                      const CalibrationFit& fit, const std::string& reference_name, int gyro_count) {
  out << "Mean residual per sequence [V], measured - predicted (cf. seed Fig. 4): '" << reference_name
      << "' | new\n";
  out << " seq";
  for (int i = 1; i <= gyro_count; ++i) out << cal_format("     g%d ref        g%d new  ", i, i);
  out << "\n";
  for (std::size_t j = 0; j < motion.sequences.size(); ++j) {
    out << cal_format(" %3d", motion.sequences[j].sequence);
    for (int i = 0; i < gyro_count; ++i) {
      const auto row = static_cast<Eigen::Index>(j);
      out << cal_format("  %+10.3e  %+10.3e ", reference_fit.sequence_residual_V(row, i),
                        fit.sequence_residual_V(row, i));
    }
    out << "\n";
  }
  out << " RMS";
  for (int i = 0; i < gyro_count; ++i) {
    out << cal_format("  %10.3e  %10.3e ", reference_fit.sequence_rms_V(i), fit.sequence_rms_V(i));
  }
  out << "\n ratio ref/new:";
  for (int i = 0; i < gyro_count; ++i) {
    out << cal_format("  g%d %.3g", i + 1, reference_fit.sequence_rms_V(i) / fit.sequence_rms_V(i));
  }
  out << "\n\n";
}

Result<CalibrationOptions> estimator_options(const CalibrationReportOptions& o) {
  CalibrationOptions options;
  options.method = o.method;
  options.bias_model = o.bias_model;
  if (options.method == CalibrationMethod::kBatch && o.bias_model != BiasModel::kBody) {
    return bad_input(ErrorSubject("bias_model"),
                     "applies to method sixteen only (batch fits the bias per sample)");
  }
  return options;
}

// The latitude (option or comment; a note on stderr when the option overrides the file's).
Result<double> latitude_of(const TurntableRows& log, const CalibrationReportOptions& o, std::ostream& err) {
  const std::string option = name_of(o.names, "latitude_deg");
  auto latitude = latitude_from(log, o.latitude_deg, option);
  if (!latitude) return latitude;
  if (o.latitude_deg) {
    if (const auto in_file = log.meta("latitude_deg")) {
      err << name_of(o.names, "command") << ": using " << option << " " << *o.latitude_deg
          << " (the file says " << *in_file << ")\n";
    }
  }
  return latitude;
}

// --compare: the other calibration, with as many gyros as the log.
Result<std::optional<Calibration>> reference_of(const TurntableRows& log, const CalibrationReportOptions& o) {
  if (o.compare_path.empty()) return std::optional<Calibration>{};
  auto ref = read_calibration(o.compare_path);
  if (!ref) return ref.error();
  if (ref->gyro_count() != log.gyro_count()) {
    return bad_input(o.compare_path + ": has " + std::to_string(ref->gyro_count()) + " gyros, " +
                     o.turntable_path + " has " + std::to_string(log.gyro_count()));
  }
  return std::optional<Calibration>(std::move(ref.value()));
}

// --noise: one noise section per gyro of the log, from another calibration file.
Status noise_model_of(const TurntableRows& log, const CalibrationReportOptions& o,
                      CalibrationOptions& options) {
  if (o.noise_path.empty()) return ok_status();
  auto cal = read_calibration(o.noise_path);
  if (!cal) return cal.error();
  if (cal->gyro_count() != log.gyro_count()) {
    return bad_input(o.noise_path + ": has " + std::to_string(cal->gyro_count()) + " gyros, " +
                     o.turntable_path + " has " + std::to_string(log.gyro_count()));
  }
  options.noise.clear();
  for (const auto& g : cal->gyros) {
    if (!g.noise)
      return bad_input(o.noise_path + ": gyro " + std::to_string(g.id) + " has no 'noise:' section");
    options.noise.push_back(*g.noise);
  }
  options.bias_instability_correlation_s = o.bias_instability_correlation_s;
  return ok_status();
}

// With the seed's eq. 11 bias: how far it lies from the body-model bias.
void print_seed_bias_difference(std::ostream& out, const TurntableRows& log, const TurntableMotion& motion,
                                const CalibrationOptions& options, const CalibrationResult& result) {
  CalibrationOptions body = options;
  body.bias_model = BiasModel::kBody;
  auto body_result = calibrate(log, motion, body);
  if (!body_result) return;
  out << "Seed eq. 11 bias minus body-model bias [V]:";
  for (int i = 0; i < log.gyro_count(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    out << cal_format("  g%d %+.3e", i + 1,
                      result.calibration.gyros[k].bias_V - body_result->calibration.gyros[k].bias_V);
  }
  out << "\n(eq. 11 subtracts the lab-frame Earth rate although the body is rotated; see "
         "docs/calibration.md)\n\n";
}

// The tables on standard output: plan, estimates, the comparison, the seed-bias note, what 1σ means.
Status print_calibration_report(std::ostream& out, const TurntableRows& log, const TurntableMotion& motion,
                                const CalibrationOptions& options, const CalibrationResult& result,
                                const std::optional<Calibration>& reference,
                                const std::string& reference_name) {
  print_plan(out, log, motion);
  print_estimates(out, result, options, reference, reference_name);
  if (reference) {
    auto reference_fit = evaluate_calibration(log, motion, *reference);
    if (!reference_fit) return reference_fit.error();
    print_comparison(out, motion, *reference_fit, result.fit, reference_name, log.gyro_count());
  }
  if (options.method == CalibrationMethod::kSixteen && options.bias_model == BiasModel::kSeed)
    print_seed_bias_difference(out, log, motion, options, result);
  out << "1-sigma: "
      << (options.method == CalibrationMethod::kSixteen
              ? "per-sequence standard deviation of the mean, propagated"
              : "residual covariance of the fit");
  if (options.noise.empty()) {
    out << "; white noise within a sequence assumed, so correlated noise (bias instability, rate "
           "random walk) makes them optimistic (--noise adds it).\n";
  } else {
    out << ", plus the covariance of the sequence means from the gyros' bias instability and rate "
           "random walk (--noise).\n";
  }
  return ok_status();
}

}  // namespace

Result<CalibrationResult> write_calibration_report(const CalibrationReportOptions& o, std::ostream& out,
                                                   std::ostream& err) {
  auto options = estimator_options(o);
  if (!options) return options.error();
  RunFiles files;
  files.add_input(o.turntable_path, name_of(o.names, "turntable_path"));
  if (!o.compare_path.empty()) files.add_input(o.compare_path, name_of(o.names, "compare_path"));
  if (!o.noise_path.empty()) files.add_input(o.noise_path, name_of(o.names, "noise_path"));
  auto cal_out = files.add(o.output_path, name_of(o.names, "output_path"));
  if (!cal_out) return cal_out.error();
  auto log = std::make_unique<TurntableFileRows>();  // the rows are read again at each pass, never held
  if (Status s = log->open(o.turntable_path); !s) return s.error();
  auto latitude = latitude_of(*log, o, err);
  if (!latitude) return latitude.error();
  options->unit = !o.unit.empty() ? o.unit : log->meta("unit").value_or("tetra-1");
  auto reference = reference_of(*log, o);
  if (!reference) return reference.error();
  if (Status s = noise_model_of(*log, o, *options); !s) return s.error();
  auto motion = analyze_turntable(*log, *latitude);
  if (!motion) return motion.error();
  auto result = calibrate(*log, *motion, *options);
  if (!result) return result.error();
  if (Status s = print_calibration_report(out, *log, *motion, *options, *result, *reference, o.compare_path);
      !s)
    return s.error();
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status s = write_calibration(**cal_out, result->calibration, meta); !s) return s.error();
  if (Status s = files.commit(); !s) return s.error();
  err << name_of(o.names, "command") << ": wrote " << o.output_path << "\n";
  return result;
}

}  // namespace tetra::report
