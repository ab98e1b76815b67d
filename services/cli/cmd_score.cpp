// tetra score — attitude error of an estimate against the simulator's truth: per axis and total, NEES,
// fractions within 1/2/3σ, integrated angle about an axis, and the error against its ±3σ envelope as a plot.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/report/gnuplot.hpp"
#include "tetra/report/score_plot.hpp"
#include "tetra/core/attitude_score.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"

namespace tetra::cli {

namespace {

//! "x", "y", "z" or three numbers "a,b,c" (normalized); bad input naming --axis otherwise.
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
    if (!value) return bad_input("--axis '" + text + "': expected x, y, z or three numbers a,b,c");
    v(k) = *value;
    start = comma + 1;
  }
  if (!(v.norm() > 0.0)) return bad_input("--axis '" + text + "': the zero vector has no direction");
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

void print_errors(const AttitudeScore& s) {
  char line[160];
  std::cout << "  error [deg]        x              y              z              total\n";
  std::snprintf(line, sizeof line, "    RMS       %13.6e  %13.6e  %13.6e  %13.6e\n", s.rms_B_deg(0),
                s.rms_B_deg(1), s.rms_B_deg(2), s.rms_total_deg);
  std::cout << line;
  std::snprintf(line, sizeof line, "    max |e|   %13.6e  %13.6e  %13.6e  %13.6e\n", s.max_abs_B_deg(0),
                s.max_abs_B_deg(1), s.max_abs_B_deg(2), s.max_total_deg);
  std::cout << line;
  const Eigen::Vector3d& last = s.epochs.back().error_B_deg;
  std::snprintf(line, sizeof line, "    final     %+13.6e  %+13.6e  %+13.6e  %13.6e   (t = %g s)\n", last(0),
                last(1), last(2), s.final_total_deg, s.epochs.back().time_s);
  std::cout << line;
}

void print_consistency(const AttitudeScore& s) {
  const std::string left_out =
      s.no_sigma_epochs ? " (" + std::to_string(s.no_sigma_epochs) + " with sigma 0 or nan left out)" : "";
  if (s.per_axis_sigma) {
    std::cout << "  NEES, 3 dof (expectation 3): mean " << fixed_or_na(s.mean_nees, 3) << " over "
              << s.sigma_epochs << " epochs" << left_out << '\n';
    const char* axes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      std::cout << "  within 1/2/3 sigma, " << axes[k] << ": "
                << percents({s.within_B[0](k), s.within_B[1](k), s.within_B[2](k)})
                << "   (Gaussian: 68.3 / 95.4 / 99.7 %)\n";
    }
  } else {
    std::cout << "  normalized error |e|^2/sigma^2 (expectation 1): mean " << fixed_or_na(s.mean_nees, 3)
              << " over " << s.sigma_epochs << " epochs" << left_out << '\n';
  }
  std::cout << "  within 1/2/3 sigma, total angle: " << percents(s.within_total)
            << "   (isotropic 3-D Gaussian: 60.8 / 99.3 / 100.0 %)\n";
}

void print_report(const AttitudeScore& s, const std::string& att, const std::string& truth,
                  const ScoreOptions& o, const std::string& axis_name) {
  std::cout << "tetra score: " << att << " against " << truth << '\n';
  std::cout << "  epochs: " << s.epochs.size() << " scored (" << s.exact_matches << " at a truth row within "
            << o.time_tolerance_s << " s, " << s.interpolated << " against truth interpolated between rows), "
            << s.outside_truth << " outside the truth's time span\n";
  std::cout << "  sigma: "
            << (s.per_axis_sigma ? "per axis (sigma_x_deg, sigma_y_deg, sigma_z_deg)"
                                 : "total sigma_deg (the file has no per-axis columns)")
            << '\n';
  print_errors(s);
  print_consistency(s);
  std::cout << "  integrated angle about " << axis_name << ": " << fixed_or_na(s.angle_axis_deg, 2)
            << " deg (truth " << fixed_or_na(s.truth_angle_axis_deg, 2)
            << " deg); about x, y, z: " << fixed_or_na(s.angle_B_deg(0), 2) << ", "
            << fixed_or_na(s.angle_B_deg(1), 2) << ", " << fixed_or_na(s.angle_B_deg(2), 2) << " deg\n";
}

nlohmann::json vec(const Eigen::Vector3d& v) {
  nlohmann::json a = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) a.push_back(std::isfinite(v(k)) ? nlohmann::json(v(k)) : nlohmann::json());
  return a;
}

nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

std::string format_json(const AttitudeScore& s, const ScoreOptions& o, const std::string& axis_name,
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
  j["error_deg"] = {{"rms_xyz", vec(s.rms_B_deg)},
                    {"rms_total", s.rms_total_deg},
                    {"max_abs_xyz", vec(s.max_abs_B_deg)},
                    {"max_total", s.max_total_deg},
                    {"final_xyz", vec(s.epochs.back().error_B_deg)},
                    {"final_total", s.final_total_deg}};
  j["nees"] = {{"dof", s.nees_dof},
               {"mean", num(s.mean_nees)},
               {"epochs", s.sigma_epochs},
               {"no_sigma_epochs", s.no_sigma_epochs}};
  nlohmann::json within_axis = nlohmann::json::array();
  for (const auto& w : s.within_B) within_axis.push_back(vec(w));
  j["within_1_2_3_sigma"] = {
      {"xyz", s.per_axis_sigma ? within_axis : nlohmann::json()},
      {"total", {num(s.within_total[0]), num(s.within_total[1]), num(s.within_total[2])}}};
  j["integrated_angle_deg"] = {{"axis", axis_name},
                               {"axis_B", vec(o.axis_B)},
                               {"estimate", s.angle_axis_deg},
                               {"truth", s.truth_angle_axis_deg},
                               {"estimate_xyz", vec(s.angle_B_deg)},
                               {"truth_xyz", vec(s.truth_angle_B_deg)}};
  return j.dump(1) + "\n";
}

}  // namespace

int cmd_score(int argc, char** argv) {
  CLI::App app(
      "Score an attitude estimate (tetra replay --attitude) against the truth (tetra sim --truth): error per "
      "body axis and total, NEES and the fractions of epochs within 1/2/3 sigma (per-axis sigma columns when "
      "present, else sigma_deg), the integrated angle about an axis, and the error against its +-3 sigma "
      "envelope as a plot. Rows are matched by time: a truth row within --time-tolerance, else the truth "
      "interpolated between its rows; rows outside the truth's time span are counted, not scored.",
      "score");
  std::string att_path;
  std::string truth_path;
  std::string plot_path;
  std::string json_path;
  std::string axis_name = "y";
  ScoreOptions options;
  app.add_option("ATT.csv", att_path, "attitude: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,...")
      ->required();
  app.add_option("TRUTH.csv", truth_path, "truth: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps")->required();
  app.add_option("--plot", plot_path, "write the error per axis against +-3 sigma as a PNG (needs gnuplot)");
  app.add_option("--json", json_path, "write the figures as JSON");
  app.add_option("--axis", axis_name,
                 "axis of the integrated angle: x, y, z or a body vector a,b,c (default y, the seed's turn)");
  app.add_option("--time-tolerance", options.time_tolerance_s,
                 "[s] an attitude row and a truth row this close in time are the same epoch (default 1e-6)");
  if (auto status = parse(app, argc, argv)) return *status;

  const std::string cmd = "score";
  auto axis = parse_axis(axis_name);
  if (!axis) return report(cmd, axis.error());
  options.axis_B = *axis;
  if (!(options.time_tolerance_s >= 0.0 && std::isfinite(options.time_tolerance_s)))
    return report(cmd, bad_input("--time-tolerance: expected a number of seconds >= 0"));

  RunFiles files;
  files.add_input(att_path, "ATT.csv");
  files.add_input(truth_path, "TRUTH.csv");
  OutputFile* plot_out = nullptr;
  OutputFile* json_out = nullptr;
  if (Status s = files.add_outputs({{plot_path, "--plot", &plot_out}, {json_path, "--json", &json_out}}); !s)
    return report(cmd, s.error());

  auto attitude = read_attitude_series(att_path, true);
  if (!attitude) return report(cmd, attitude.error());
  auto truth = read_attitude_series(truth_path, false);
  if (!truth) return report(cmd, truth.error());
  auto score = score_attitude(*attitude, *truth, options);
  if (!score) {
    return report(cmd, score.error(),
                  {{"axis_B", "--axis: {message}"}, {"time_tolerance_s", "--time-tolerance: {message}"}});
  }

  print_report(*score, att_path, truth_path, options, axis_name);
  if (json_out) {
    if (Status s = json_out->write(format_json(*score, options, axis_name, files.input_paths())); !s)
      return report(cmd, s.error());
  }
  if (plot_out) {
    if (Status s = report::write_score_plot(*plot_out, *score, "tetra score: " + att_path + " - " + truth_path);
        !s)
      return report(cmd, s.error(), {{report::kPlotSubject, "--plot: {message}"}});
  }
  if (Status s = files.commit(); !s) return report(cmd, s.error());
  return kExitOk;
}

}  // namespace tetra::cli
