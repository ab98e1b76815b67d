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
#include "tetra/report/gnuplot.hpp"
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
  auto temp = report::TempDir::create("tetra-allan");
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
          report::gp_quote("tetra allan: overlapping Allan deviation, " + percent(confidence) +
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
    body += "plot " + report::gp_quote(data_file) +
            " using 1:3:4 with filledcurves lc rgb '#c6dbef' title 'confidence band', \\\n";
    body += "  " + report::gp_quote(data_file) +
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
  if (Status s = report::run_gnuplot(dir, png_path, static_cast<int>(cols * 640), static_cast<int>(rows * 480),
                             defs + body, "--plot");
      !s)
    return s;
  auto image = read_input(png_path, kMaxTableBytes);
  if (!image) return failure("--plot: gnuplot wrote no image");
  return png.write(*image);
}

struct AllanOptions {
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
};

void add_options(CLI::App& app, AllanOptions& o) {
  app.add_option("log", o.log_path,
                 "gyro log (CSV, or HDF5 when named .h5; docs/formats.md): time_s,g1..gN; volts, or deg/s "
                 "with '# units=dps'")
      ->required();
  app.add_option("--calibration", o.cal_path, "calibration YAML: volts become deg/s as (g - bias)/scale");
  app.add_flag("--update-calibration", o.update_cal,
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

// The options' combinations and ranges, and the averaging times parsed.
Result<allan::TauSpec> check_options(const AllanOptions& o) {
  if (o.update_cal && o.cal_path.empty())
    return bad_input("--update-calibration needs --calibration CAL.yaml");
  if (!o.kalibr_path.empty() && o.cal_path.empty())
    return bad_input("--kalibr needs --calibration CAL.yaml (the gyro axes)");
  if (!(o.dt_tolerance > 0.0 && o.dt_tolerance < 0.5))
    return bad_input("--dt-tolerance " + num(o.dt_tolerance) + ": expected a fraction in (0, 0.5)");
  if (!(o.confidence > 0.0 && o.confidence < 1.0))
    return bad_input("--confidence " + num(o.confidence) + ": expected a level in (0, 1)");
  return allan::parse_tau_spec(o.taus);
}

struct AllanOutputs {
  OutputFile* csv = nullptr;
  OutputFile* json = nullptr;
  OutputFile* plot = nullptr;
  OutputFile* kalibr = nullptr;
  OutputFile* cal = nullptr;  // --update-calibration: the calibration file, replaced
};

Result<AllanOutputs> open_outputs(RunFiles& files, const AllanOptions& o) {
  AllanOutputs out;
  if (Status s = files.add_outputs({{o.csv_path, "--csv", &out.csv},
                                    {o.json_path, "--json", &out.json},
                                    {o.plot_path, "--plot", &out.plot},
                                    {o.kalibr_path, "--kalibr", &out.kalibr}});
      !s)
    return s.error();
  if (o.update_cal) {
    auto cal = files.add(o.cal_path, "--update-calibration", o.cal_path);
    if (!cal) return cal.error();
    out.cal = *cal;
  }
  return out;
}

// The log read block by block, never whole (docs/allan.md: memory). Progress goes to stderr when a
// person is watching it; otherwise stderr carries only the one-line reason of a failure.
Result<allan::LogAllan> analyse(const AllanOptions& o, const allan::TauSpec& taus, const Calibration* cal) {
  const bool progress = ::isatty(STDERR_FILENO) != 0;
  const auto t0 = Clock::now();
  if (progress) std::cerr << "tetra allan: reading and analysing " << o.log_path << "\n";
  allan::LogAllanOptions options;
  options.allan.taus = taus;
  options.allan.confidence = o.confidence;
  options.dt_tolerance = o.dt_tolerance;
  options.gyros = o.gyros;
  options.calibration = cal;
  auto analysis = allan::analyze_gyro_log_file(o.log_path, options);
  if (!analysis) return analysis;
  if (analysis->log_units_dps && cal != nullptr) {
    std::cerr << "tetra allan: the log is already in deg/s; the calibration is used only for "
                 "--update-calibration\n";
  }
  if (progress) std::cerr << "tetra allan: analysed in " << sci(seconds_since(t0)) << " s total\n";
  return analysis;
}

void print_report(const AllanOptions& o, const allan::LogAllan& analysis, bool calibrated) {
  std::cout << o.log_path << ": " << analysis.epochs << " epochs";
  if (analysis.missing_epochs > 0)
    std::cout << " (+" << analysis.missing_epochs << " missing epochs as gaps)";
  std::cout << ", sampling interval " << num(analysis.tau0_s) << " s (from the time column)"
            << (calibrated && !analysis.log_units_dps ? ", calibrated with " + o.cal_path : std::string())
            << "\n\n";
  std::cout << allan::format_table(analysis);
}

Status write_outputs(const AllanOutputs& out, const allan::LogAllan& analysis,
                     std::optional<Calibration>& cal, const Metadata& meta, double confidence) {
  if (out.csv) {
    std::string text;
    for (const auto& [key, value] : meta) append_metadata(text, key, value);
    if (Status s = out.csv->write(text + allan::format_csv(analysis)); !s) return s;
  }
  if (out.json) {
    if (Status s = out.json->write(allan::format_json(analysis, meta)); !s) return s;
  }
  if (out.plot) {
    if (Status s = write_plot(*out.plot, analysis, confidence); !s) return s;
  }
  if (out.kalibr) {
    auto noise = allan::kalibr_gyro_noise(analysis, *cal);
    if (!noise) return noise.error();
    const std::string rostopic = "/tetra/" + service::ros2_name(cal->unit) + "/imu";  // the ROS 2 view's
    if (Status s = out.kalibr->write(allan::format_kalibr(*noise, rostopic)); !s) return s;
  }
  if (out.cal) {
    if (Status s = allan::update_calibration_noise(*cal, analysis); !s) return s;
    if (Status s = write_calibration(*out.cal, *cal, meta); !s) return s;
  }
  return ok_status();
}

// Options checked, outputs opened, calibration read; the analysis; its report and files.
Status run_allan(const AllanOptions& o) {
  auto taus = check_options(o);
  if (!taus) return taus.error();
  RunFiles files;
  files.add_input(o.log_path, "log");
  if (!o.cal_path.empty()) files.add_input(o.cal_path, "--calibration");
  auto out = open_outputs(files, o);
  if (!out) return out.error();
  std::optional<Calibration> cal;
  if (!o.cal_path.empty()) {
    auto c = read_calibration(o.cal_path);
    if (!c) return c.error();
    cal = std::move(c.value());
  }
  auto analysis = analyse(o, *taus, cal ? &*cal : nullptr);
  if (!analysis) return analysis.error();
  print_report(o, *analysis, cal.has_value());
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status s = write_outputs(*out, *analysis, cal, meta, o.confidence); !s) return s;
  if (Status s = files.commit(); !s) return s;
  if (out->cal) std::cerr << "tetra allan: noise terms written to " << o.cal_path << "\n";
  return ok_status();
}

}  // namespace

int cmd_allan(int argc, char** argv) {
  CLI::App app(
      "Overlapping Allan deviation of each gyro of a log, with chi-squared confidence intervals "
      "(NIST SP 1065), and the IEEE Std 952-1997 noise terms Q, N, B, K, R fitted by non-negative "
      "weighted least squares; terms the data do not show are reported as NO (null).",
      "allan");
  AllanOptions options;
  add_options(app, options);
  if (auto status = parse(app, argc, argv)) return *status;
  if (Status s = run_allan(options); !s) {
    return report("allan", s.error(),
                  {{allan::kSubjectTaus, "--taus: {message}"},
                   {allan::kSubjectGyros, "--gyro {value}: {message}"},
                   {allan::kSubjectOtherGyros, "{message} (--gyro N analyses the others alone)"},
                   {allan::kSubjectNoiseUpdate, "--update-calibration: {message}"},
                   {allan::kSubjectKalibr, "--kalibr: {message}"}});
  }
  return kExitOk;
}

}  // namespace tetra::cli
