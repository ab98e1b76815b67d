// tetra allan — Allan deviation with confidence intervals and the IEEE 952 noise terms of a gyro log.
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "gnuplot.hpp"
#include "tetra/core/allan.hpp"
#include "tetra/core/allan_kalibr.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/service/ros2_view_config.hpp"

namespace tetra::cli {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string num(double v) {
  std::string s;
  append_double(s, v);
  return s;
}

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

std::string percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", 100.0 * fraction);
  return buf;
}

// Log-log plot: per gyro a panel with the Allan deviation, its confidence band, the fitted curve and
// the observed terms. Runs gnuplot (pngcairo, else png).
Status write_plot(OutputFile& png, const allan::LogAllan& analysis, double confidence) {
  auto temp = TempDir::create("tetra-allan");
  if (!temp) return failure("--plot: " + temp.error().message);
  const std::filesystem::path& dir = temp->path();

  const std::size_t panels = analysis.gyros.size();
  const std::size_t cols = panels <= 1 ? 1 : 2;
  const std::size_t rows = (panels + cols - 1) / cols;
  std::string body;
  body += "set logscale xy\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\nset format y '10^{%L}'\n";
  body +=
      "set format x '10^{%L}'\nset key bottom left font ',8' spacing 0.9\nset xlabel 'averaging time "
      "{/Symbol t} [s]'\n";
  body += "set ylabel 'Allan deviation [" + analysis.units + "]'\n";
  body += "set multiplot layout " + std::to_string(rows) + "," + std::to_string(cols) + " title " +
          gp_quote("tetra allan: overlapping Allan deviation, " + percent(confidence) +
                   " % confidence band, IEEE 952 fit") +
          "\n";
  const std::array<const char*, allan::kTermCount> colors = {"#9467bd", "#2ca02c", "#ff7f0e", "#d62728",
                                                             "#8c564b"};
  for (const allan::GyroAllan& g : analysis.gyros) {
    const std::string data_file = (dir / ("gyro" + std::to_string(g.id) + ".dat")).string();
    std::string data;
    for (const allan::AdevPoint& p : g.result.points) {
      data += num(p.tau_s) + ' ' + num(p.adev) + ' ' + num(p.adev_lo) + ' ' + num(p.adev_hi) + '\n';
    }
    if (Status s = write_text_file(data_file, data); !s) return s;
    const allan::NoiseFit& f = g.result.fit;
    const double tau_lo = g.result.points.front().tau_s;
    const double tau_hi = g.result.points.back().tau_s;
    body += "set title 'gyro " + std::to_string(g.id) + "'\n";
    body += "set xrange [" + num(tau_lo / 1.5) + ":" + num(tau_hi * 1.5) + "]\n";
    std::string model = "sqrt(0";
    for (int k = 0; k < allan::kTermCount; ++k) {
      const double v = f.value[static_cast<std::size_t>(k)];
      model += "+" + num(v * v) + "*b" + std::string(allan::term_symbol(k)) + "(x)";
    }
    model += ")";
    body += "plot " + gp_quote(data_file) +
            " using 1:3:4 with filledcurves lc rgb '#c6dbef' title 'confidence band', \\\n";
    body += "  " + gp_quote(data_file) +
            " using 1:2 with linespoints pt 7 ps 0.5 lw 1.5 lc rgb '#1f4e9c' title 'ADEV', \\\n";
    body += "  " + model + " with lines lw 2 dt 2 lc rgb 'black' title 'fit'";
    for (int k = 0; k < allan::kTermCount; ++k) {
      const auto v = f.reported(k);
      if (!v) continue;
      body += ", \\\n  sqrt(" + num(*v * *v) + "*b" + std::string(allan::term_symbol(k)) +
              "(x)) with lines lw 1 lc rgb '" + colors[static_cast<std::size_t>(k)] + "' title '" +
              allan::term_symbol(k) + " = " + sci(*v) + "'";
    }
    body += "\n";
  }
  body += "unset multiplot\n";
  const std::string defs =
      "bQ(t) = 3.0/(t*t)\nbN(t) = 1.0/t\nbB(t) = 2.0*log(2.0)/pi\nbK(t) = t/3.0\nbR(t) = t*t/2.0\n";
  // gnuplot writes into the temporary directory; the image reaches --plot through the output layer.
  const std::string png_path = (dir / "plot.png").string();
  if (Status s = run_gnuplot(dir, png_path, static_cast<int>(cols * 640), static_cast<int>(rows * 480),
                             defs + body, "--plot");
      !s)
    return s;
  auto image = read_input(png_path, kMaxTableBytes);
  if (!image) return failure("--plot: gnuplot wrote no image");
  return png.write(*image);
}

}  // namespace

int cmd_allan(int argc, char** argv) {
  CLI::App app(
      "Overlapping Allan deviation of each gyro of a log, with chi-squared confidence intervals "
      "(NIST SP 1065), and the IEEE Std 952-1997 noise terms Q, N, B, K, R fitted by non-negative "
      "weighted least squares; terms the data do not show are reported as NO (null).",
      "allan");
  std::string log_path;
  std::string cal_path;
  bool update_cal = false;
  std::vector<int> gyros;
  std::string taus = "default";
  std::string csv_path;
  std::string json_path;
  std::string plot_path;
  std::string kalibr_path;
  double confidence = allan::kOneSigmaConfidence;
  double dt_tolerance = 0.05;
  app.add_option("log", log_path,
                 "gyro log (CSV, or HDF5 when named .h5; docs/formats.md): time_s,g1..gN; volts, or deg/s "
                 "with '# units=dps'")
      ->required();
  app.add_option("--calibration", cal_path, "calibration YAML: volts become deg/s as (g - bias)/scale");
  app.add_flag("--update-calibration", update_cal,
               "write the fitted terms into the calibration file's noise: sections (needs --calibration)");
  app.add_option("--gyro", gyros, "analyse only this gyro (1..N); may be repeated");
  app.add_option("--taus", taus,
                 "averaging times: default (about 10 per decade), octave, decade, all, or a list in seconds "
                 "like 0.1,1,10");
  app.add_option("--csv", csv_path, "write gyro,tau_s,adev,adev_lo,adev_hi,n");
  app.add_option("--json", json_path, "write the noise terms as JSON (null = not observed)");
  app.add_option("--plot", plot_path, "write a log-log PNG plot (needs gnuplot)");
  app.add_option(
      "--kalibr", kalibr_path,
      "write Kalibr's imu.yaml: gyroscope noise density and random walk of the body axes, in rad/s "
      "(needs --calibration)");
  app.add_option("--confidence", confidence,
                 "two-sided confidence level of the intervals (default 0.683 = 1 sigma)");
  app.add_option("--dt-tolerance", dt_tolerance,
                 "allowed deviation of a time step from a whole multiple of the sampling interval, relative "
                 "(default 0.05)");
  if (auto status = parse(app, argc, argv)) return *status;

  const std::string cmd = "allan";
  if (update_cal && cal_path.empty())
    return report(cmd, bad_input("--update-calibration needs --calibration CAL.yaml"));
  if (!kalibr_path.empty() && cal_path.empty())
    return report(cmd, bad_input("--kalibr needs --calibration CAL.yaml (the gyro axes)"));
  if (!(dt_tolerance > 0.0 && dt_tolerance < 0.5)) {
    return report(cmd,
                  bad_input("--dt-tolerance " + num(dt_tolerance) + ": expected a fraction in (0, 0.5)"));
  }
  if (!(confidence > 0.0 && confidence < 1.0)) {
    return report(cmd, bad_input("--confidence " + num(confidence) + ": expected a level in (0, 1)"));
  }
  auto tau_spec = allan::parse_tau_spec(taus);
  if (!tau_spec) return report(cmd, tau_spec.error());

  RunFiles files;
  files.add_input(log_path, "log");
  if (!cal_path.empty()) files.add_input(cal_path, "--calibration");
  OutputFile* csv_out = nullptr;
  OutputFile* json_out = nullptr;
  OutputFile* plot_out = nullptr;
  OutputFile* kalibr_out = nullptr;
  OutputFile* cal_out = nullptr;
  if (Status s = files.add_outputs({{csv_path, "--csv", &csv_out},
                                    {json_path, "--json", &json_out},
                                    {plot_path, "--plot", &plot_out},
                                    {kalibr_path, "--kalibr", &kalibr_out}});
      !s)
    return report(cmd, s.error());
  if (update_cal) {
    auto out = files.add(cal_path, "--update-calibration", cal_path);
    if (!out) return report(cmd, out.error());
    cal_out = *out;
  }

  std::optional<Calibration> cal;
  if (!cal_path.empty()) {
    auto c = read_calibration(cal_path);
    if (!c) return report(cmd, c.error());
    cal = std::move(c.value());
  }

  // Progress goes to stderr when a person is watching it; otherwise stderr carries only the
  // one-line reason of a failure (the exit-status contract).
  const bool progress = ::isatty(STDERR_FILENO) != 0;
  const auto t0 = Clock::now();
  if (progress) std::cerr << "tetra allan: reading and analysing " << log_path << "\n";

  allan::LogAllanOptions options;
  options.allan.taus = *tau_spec;
  options.allan.confidence = confidence;
  options.dt_tolerance = dt_tolerance;
  options.gyros = gyros;
  options.calibration = cal ? &*cal : nullptr;
  // The log is read block by block, never whole (docs/allan.md: memory).
  auto analysis = allan::analyze_gyro_log_file(log_path, options);
  if (!analysis) return report(cmd, analysis.error());
  if (analysis->log_units_dps && cal) {
    std::cerr << "tetra allan: the log is already in deg/s; the calibration is used only for "
                 "--update-calibration\n";
  }
  if (progress) std::cerr << "tetra allan: analysed in " << sci(seconds_since(t0)) << " s total\n";

  std::cout << log_path << ": " << analysis->epochs << " epochs";
  if (analysis->missing_epochs > 0)
    std::cout << " (+" << analysis->missing_epochs << " missing epochs as gaps)";
  std::cout << ", sampling interval " << num(analysis->tau0_s) << " s (from the time column)"
            << (cal && !analysis->log_units_dps ? ", calibrated with " + cal_path : std::string()) << "\n\n";
  std::cout << allan::format_table(*analysis);

  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (csv_out) {
    std::string text;
    for (const auto& [key, value] : meta) append_metadata(text, key, value);
    if (Status s = csv_out->write(text + allan::format_csv(*analysis)); !s) return report(cmd, s.error());
  }
  if (json_out) {
    if (Status s = json_out->write(allan::format_json(*analysis, meta)); !s) return report(cmd, s.error());
  }
  if (plot_out) {
    if (Status s = write_plot(*plot_out, *analysis, confidence); !s) return report(cmd, s.error());
  }
  if (kalibr_out) {
    auto noise = allan::kalibr_gyro_noise(*analysis, *cal);
    if (!noise) return report(cmd, noise.error());
    const std::string rostopic = "/tetra/" + service::ros2_name(cal->unit) + "/imu";  // the ROS 2 view's
    if (Status s = kalibr_out->write(allan::format_kalibr(*noise, rostopic)); !s)
      return report(cmd, s.error());
  }
  if (cal_out) {
    if (Status s = allan::update_calibration_noise(*cal, *analysis); !s) return report(cmd, s.error());
    if (Status s = write_calibration(*cal_out, *cal, meta); !s) return report(cmd, s.error());
  }
  if (Status s = files.commit(); !s) return report(cmd, s.error());
  if (cal_out) std::cerr << "tetra allan: noise terms written to " << cal_path << "\n";
  return kExitOk;
}

}  // namespace tetra::cli
