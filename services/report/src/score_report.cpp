// The score report of `tetra score` (tetra/report/score_report.hpp).
#include "tetra/report/score_report.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tetra/core/csv.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/report/score_plot.hpp"

namespace tetra::report {

namespace {

//! "x", "y", "z" or three numbers "a,b,c" (normalized); bad input about kSubjectAxis otherwise.
Result<Eigen::Vector3d> parse_axis(const std::string& text) {
  if (text == "x") return Eigen::Vector3d(Eigen::Vector3d::UnitX());
  if (text == "y") return Eigen::Vector3d(Eigen::Vector3d::UnitY());
  if (text == "z") return Eigen::Vector3d(Eigen::Vector3d::UnitZ());
  Eigen::Vector3d v;
  std::size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t comma = k < 2 ? text.find(',', start) : text.size();
    const auto value =
        comma == std::string::npos ? std::nullopt : parse_decimal(text.substr(start, comma - start));
    if (!value) return bad_input(ErrorSubject(kSubjectAxis, text), "expected x, y, z or three numbers a,b,c");
    v(k) = *value;
    start = comma + 1;
  }
  if (!(v.norm() > 0.0))
    return bad_input(ErrorSubject(kSubjectAxis, text), "the zero vector has no direction");
  return Eigen::Vector3d(v.normalized());
}

std::string fixed_or_na(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  std::string s;
  append_fixed(s, v, decimals);
  return s;
}

std::string percents(const std::array<double, 3>& f) {
  return fixed_or_na(100.0 * f[0], 1) + " / " + fixed_or_na(100.0 * f[1], 1) + " / " +
         fixed_or_na(100.0 * f[2], 1) + " %";
}

void print_errors(std::ostream& out, const AttitudeScore& s) {
  char line[160];
  out << "  error [deg]        x              y              z              total\n";
  std::snprintf(line, sizeof line, "    RMS       %13.6e  %13.6e  %13.6e  %13.6e\n", s.rms_B_deg(0),
                s.rms_B_deg(1), s.rms_B_deg(2), s.rms_total_deg);
  out << line;
  std::snprintf(line, sizeof line, "    max |e|   %13.6e  %13.6e  %13.6e  %13.6e\n", s.max_abs_B_deg(0),
                s.max_abs_B_deg(1), s.max_abs_B_deg(2), s.max_total_deg);
  out << line;
  const Eigen::Vector3d& last = s.epochs.back().error_B_deg;
  std::snprintf(line, sizeof line, "    final     %+13.6e  %+13.6e  %+13.6e  %13.6e   (t = %g s)\n", last(0),
                last(1), last(2), s.final_total_deg, s.epochs.back().time_s);
  out << line;
}

void print_consistency(std::ostream& out, const AttitudeScore& s) {
  const std::string left_out =
      s.no_sigma_epochs ? " (" + std::to_string(s.no_sigma_epochs) + " with sigma 0 or nan left out)" : "";
  if (s.per_axis_sigma) {
    out << "  NEES, 3 dof (expectation 3): mean " << fixed_or_na(s.mean_nees, 3) << " over " << s.sigma_epochs
        << " epochs" << left_out << '\n';
    const char* axes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      out << "  within 1/2/3 sigma, " << axes[k] << ": "
          << percents({s.within_B[0](k), s.within_B[1](k), s.within_B[2](k)})
          << "   (Gaussian: 68.3 / 95.4 / 99.7 %)\n";
    }
  } else {
    out << "  normalized error |e|^2/sigma^2 (expectation 1): mean " << fixed_or_na(s.mean_nees, 3)
        << " over " << s.sigma_epochs << " epochs" << left_out << '\n';
  }
  out << "  within 1/2/3 sigma, total angle: " << percents(s.within_total)
      << "   (isotropic 3-D Gaussian: 60.8 / 99.3 / 100.0 %)\n";
}

void print_score(std::ostream& out, const AttitudeScore& s, const std::string& att, const std::string& truth,
                 const ScoreOptions& o, const std::string& axis_name) {
  out << "tetra score: " << att << " against " << truth << '\n';
  out << "  epochs: " << s.epochs.size() << " scored (" << s.exact_matches << " at a truth row within "
      << o.time_tolerance_s << " s, " << s.interpolated << " against truth interpolated between rows), "
      << s.outside_truth << " outside the truth's time span\n";
  out << "  sigma: "
      << (s.per_axis_sigma ? "per axis (sigma_x_deg, sigma_y_deg, sigma_z_deg)"
                           : "total sigma_deg (the file has no per-axis columns)")
      << '\n';
  print_errors(out, s);
  print_consistency(out, s);
  out << "  integrated angle about " << axis_name << ": " << fixed_or_na(s.angle_axis_deg, 2)
      << " deg (truth " << fixed_or_na(s.truth_angle_axis_deg, 2)
      << " deg); about x, y, z: " << fixed_or_na(s.angle_B_deg(0), 2) << ", "
      << fixed_or_na(s.angle_B_deg(1), 2) << ", " << fixed_or_na(s.angle_B_deg(2), 2) << " deg\n";
}

nlohmann::json json_vec(const Eigen::Vector3d& v) {
  nlohmann::json a = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) a.push_back(std::isfinite(v(k)) ? nlohmann::json(v(k)) : nlohmann::json());
  return a;
}

nlohmann::json json_num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

std::string format_score_json(const AttitudeScore& s, const ScoreOptions& o, const std::string& axis_name,
                              const std::vector<std::string>& inputs) {
  nlohmann::json j;
  nlohmann::json prov = nlohmann::json::object();
  for (const auto& [key, value] : provenance_metadata(provenance(inputs))) prov[key] = value;
  j["provenance"] = prov;
  j["epochs"] = {{"scored", s.epochs.size()},
                 {"exact", s.exact_matches},
                 {"interpolated", s.interpolated},
                 {"outside_truth", s.outside_truth},
                 {"time_tolerance_s", o.time_tolerance_s}};
  j["sigma"] = s.per_axis_sigma ? "per-axis" : "total";
  j["error_deg"] = {{"rms_xyz", json_vec(s.rms_B_deg)},
                    {"rms_total", s.rms_total_deg},
                    {"max_abs_xyz", json_vec(s.max_abs_B_deg)},
                    {"max_total", s.max_total_deg},
                    {"final_xyz", json_vec(s.epochs.back().error_B_deg)},
                    {"final_total", s.final_total_deg}};
  j["nees"] = {{"dof", s.nees_dof},
               {"mean", json_num(s.mean_nees)},
               {"epochs", s.sigma_epochs},
               {"no_sigma_epochs", s.no_sigma_epochs}};
  nlohmann::json within_axis = nlohmann::json::array();
  for (const auto& w : s.within_B) within_axis.push_back(json_vec(w));
  j["within_1_2_3_sigma"] = {
      {"xyz", s.per_axis_sigma ? within_axis : nlohmann::json()},
      {"total", {json_num(s.within_total[0]), json_num(s.within_total[1]), json_num(s.within_total[2])}}};
  j["integrated_angle_deg"] = {{"axis", axis_name},
                               {"axis_B", json_vec(o.axis_B)},
                               {"estimate", s.angle_axis_deg},
                               {"truth", s.truth_angle_axis_deg},
                               {"estimate_xyz", json_vec(s.angle_B_deg)},
                               {"truth_xyz", json_vec(s.truth_angle_B_deg)}};
  return j.dump(1) + "\n";
}

}  // namespace

Result<AttitudeScore> write_score_report(const ScoreReportOptions& o, std::ostream& out) {
  ScoreOptions options;
  options.time_tolerance_s = o.time_tolerance_s;
  auto axis = parse_axis(o.axis);
  if (!axis) return axis.error();
  options.axis_B = *axis;
  if (!(options.time_tolerance_s >= 0.0 && std::isfinite(options.time_tolerance_s)))
    return bad_input(ErrorSubject("time_tolerance_s"), "expected a number of seconds >= 0");

  RunFiles files;
  files.add_input(o.attitude_path, name_of(o.names, "attitude_path"));
  files.add_input(o.truth_path, name_of(o.names, "truth_path"));
  OutputFile* plot_out = nullptr;
  OutputFile* json_out = nullptr;
  const std::string plot_name = name_of(o.names, "plot_path");
  const std::string json_name = name_of(o.names, "json_path");
  if (Status s = files.add_outputs(
          {{o.plot_path, plot_name.c_str(), &plot_out}, {o.json_path, json_name.c_str(), &json_out}});
      !s)
    return s.error();

  auto attitude = read_attitude_series(o.attitude_path, true);
  if (!attitude) return attitude.error();
  auto truth = read_attitude_series(o.truth_path, false);
  if (!truth) return truth.error();
  auto score = score_attitude(*attitude, *truth, options);
  if (!score) return score.error();

  print_score(out, *score, o.attitude_path, o.truth_path, options, o.axis);
  if (json_out) {
    if (Status s = json_out->write(format_score_json(*score, options, o.axis, files.input_paths())); !s)
      return s.error();
  }
  if (plot_out) {
    const std::string title = "tetra score: " + o.attitude_path + " - " + o.truth_path;
    if (Status s = write_score_plot(*plot_out, *score, title); !s) return s.error();
  }
  if (Status s = files.commit(); !s) return s.error();
  return score;
}

}  // namespace tetra::report
