// The Allan report of `tetra allan` (tetra/report/allan_report.hpp).
#include "tetra/report/allan_report.hpp"

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tetra/core/allan_kalibr.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/report/gnuplot.hpp"
#include "tetra/service/ros2_view_config.hpp"

namespace tetra::report {

namespace {

using AllanClock = std::chrono::steady_clock;

double seconds_since(AllanClock::time_point t0) {
  return std::chrono::duration<double>(AllanClock::now() - t0).count();
}

std::string allan_num(double v) {
  std::string s;
  append_double(s, v);
  return s;
}

std::string allan_sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

std::string allan_percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", 100.0 * fraction);
  return buf;
}

// Log-log plot: per gyro a panel with the Allan deviation, its confidence band, the fitted curve and
// the observed terms. Runs gnuplot (pngcairo, else png).
Status write_allan_plot(OutputFile& png, const allan::LogAllan& analysis, double confidence) {
  auto temp = TempDir::create("tetra-allan");
  if (!temp) return failure(ErrorSubject(kPlotSubject), temp.error().message);
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
          gp_quote("tetra allan: overlapping Allan deviation, " + allan_percent(confidence) +
                   " % confidence band, IEEE 952 fit") +
          "\n";
  const std::array<const char*, allan::kTermCount> colors = {"#9467bd", "#2ca02c", "#ff7f0e", "#d62728",
                                                             "#8c564b"};
  for (const allan::GyroAllan& g : analysis.gyros) {
    const std::string data_file = (dir / ("gyro" + std::to_string(g.id) + ".dat")).string();
    std::string data;
    for (const allan::AdevPoint& p : g.result.points) {
      data += allan_num(p.tau_s) + ' ' + allan_num(p.adev) + ' ' + allan_num(p.adev_lo) + ' ' +
              allan_num(p.adev_hi) + '\n';
    }
    if (Status s = write_text_file(data_file, data); !s) return s;
    const allan::NoiseFit& f = g.result.fit;
    const double tau_lo = g.result.points.front().tau_s;
    const double tau_hi = g.result.points.back().tau_s;
    body += "set title 'gyro " + std::to_string(g.id) + "'\n";
    body += "set xrange [" + allan_num(tau_lo / 1.5) + ":" + allan_num(tau_hi * 1.5) + "]\n";
    std::string model = "sqrt(0";
    for (int k = 0; k < allan::kTermCount; ++k) {
      const double v = f.value[static_cast<std::size_t>(k)];
      model += "+" + allan_num(v * v) + "*b" + std::string(allan::term_symbol(k)) + "(x)";
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
      body += ", \\\n  sqrt(" + allan_num(*v * *v) + "*b" + std::string(allan::term_symbol(k)) +
              "(x)) with lines lw 1 lc rgb '" + colors[static_cast<std::size_t>(k)] + "' title '" +
              allan::term_symbol(k) + " = " + allan_sci(*v) + "'";
    }
    body += "\n";
  }
  body += "unset multiplot\n";
  const std::string defs =
      "bQ(t) = 3.0/(t*t)\nbN(t) = 1.0/t\nbB(t) = 2.0*log(2.0)/pi\nbK(t) = t/3.0\nbR(t) = t*t/2.0\n";
  // gnuplot writes into the temporary directory; the image reaches --plot through the output layer.
  const std::string png_path = (dir / "plot.png").string();
  if (Status s = run_gnuplot(dir, png_path, static_cast<int>(cols * 640), static_cast<int>(rows * 480),
                             defs + body, kPlotSubject);
      !s)
    return s;
  auto image = read_input(png_path, kMaxTableBytes);
  if (!image) return failure(ErrorSubject(kPlotSubject), "gnuplot wrote no image");
  return png.write(*image);
}

// The options' combinations and ranges, and the averaging times parsed.
Result<allan::TauSpec> check_options(const AllanReportOptions& o) {
  if (o.update_calibration && o.calibration_path.empty())
    return bad_input(ErrorSubject("update_calibration"), "needs calibration_path (the file to update)");
  if (!o.kalibr_path.empty() && o.calibration_path.empty())
    return bad_input(ErrorSubject("kalibr_path"), "needs calibration_path (the gyro axes)");
  if (!(o.dt_tolerance > 0.0 && o.dt_tolerance < 0.5))
    return bad_input(ErrorSubject("dt_tolerance", allan_num(o.dt_tolerance)),
                     "expected a fraction in (0, 0.5)");
  if (!(o.confidence > 0.0 && o.confidence < 1.0))
    return bad_input(ErrorSubject("confidence", allan_num(o.confidence)), "expected a level in (0, 1)");
  return allan::parse_tau_spec(o.taus);
}

struct AllanOutputs {
  OutputFile* csv = nullptr;
  OutputFile* json = nullptr;
  OutputFile* plot = nullptr;
  OutputFile* kalibr = nullptr;
  OutputFile* cal = nullptr;  // --update-calibration: the calibration file, replaced
};

Result<AllanOutputs> open_outputs(RunFiles& files, const AllanReportOptions& o) {
  AllanOutputs out;
  const std::string csv = name_of(o.names, "csv_path");
  const std::string json = name_of(o.names, "json_path");
  const std::string plot = name_of(o.names, "plot_path");
  const std::string kalibr = name_of(o.names, "kalibr_path");
  if (Status s = files.add_outputs({{o.csv_path, csv.c_str(), &out.csv},
                                    {o.json_path, json.c_str(), &out.json},
                                    {o.plot_path, plot.c_str(), &out.plot},
                                    {o.kalibr_path, kalibr.c_str(), &out.kalibr}});
      !s)
    return s.error();
  if (o.update_calibration) {
    auto cal = files.add(o.calibration_path, name_of(o.names, "update_calibration"), o.calibration_path);
    if (!cal) return cal.error();
    out.cal = *cal;
  }
  return out;
}

// The log read block by block, never whole (docs/allan.md: memory). Progress goes to stderr when a
// person is watching it; otherwise stderr carries only the one-line reason of a failure.
Result<allan::LogAllan> analyse(const AllanReportOptions& o, const allan::TauSpec& taus,
                                const Calibration* cal, std::ostream& err) {
  const std::string command = name_of(o.names, "command");
  const auto t0 = AllanClock::now();
  if (o.progress) err << command << ": reading and analysing " << o.log_path << "\n";
  allan::LogAllanOptions options;
  options.allan.taus = taus;
  options.allan.confidence = o.confidence;
  options.dt_tolerance = o.dt_tolerance;
  options.gyros = o.gyros;
  options.calibration = cal;
  auto analysis = allan::analyze_gyro_log_file(o.log_path, options);
  if (!analysis) return analysis;
  if (analysis->log_units_dps && cal != nullptr) {
    err << command << ": the log is already in deg/s; the calibration is used only for "
        << name_of(o.names, "update_calibration") << "\n";
  }
  if (o.progress) err << command << ": analysed in " << allan_sci(seconds_since(t0)) << " s total\n";
  return analysis;
}

void print_allan(std::ostream& out, const AllanReportOptions& o, const allan::LogAllan& analysis,
                 bool calibrated) {
  out << o.log_path << ": " << analysis.epochs << " epochs";
  if (analysis.missing_epochs > 0) out << " (+" << analysis.missing_epochs << " missing epochs as gaps)";
  out << ", sampling interval " << allan_num(analysis.tau0_s) << " s (from the time column)"
      << (calibrated && !analysis.log_units_dps ? ", calibrated with " + o.calibration_path : std::string())
      << "\n\n";
  out << allan::format_table(analysis);
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
    if (Status s = write_allan_plot(*out.plot, analysis, confidence); !s) return s;
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

}  // namespace

Result<AllanReport> write_allan_report(const AllanReportOptions& o, std::ostream& table, std::ostream& err) {
  auto taus = check_options(o);
  if (!taus) return taus.error();
  RunFiles files;
  files.add_input(o.log_path, name_of(o.names, "log_path"));
  if (!o.calibration_path.empty()) files.add_input(o.calibration_path, name_of(o.names, "calibration_path"));
  auto out = open_outputs(files, o);
  if (!out) return out.error();
  std::optional<Calibration> cal;
  if (!o.calibration_path.empty()) {
    auto c = read_calibration(o.calibration_path);
    if (!c) return c.error();
    cal = std::move(c.value());
  }
  auto analysis = analyse(o, *taus, cal ? &*cal : nullptr, err);
  if (!analysis) return analysis.error();
  print_allan(table, o, *analysis, cal.has_value());
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status s = write_outputs(*out, *analysis, cal, meta, o.confidence); !s) return s.error();
  if (Status s = files.commit(); !s) return s.error();
  if (out->cal)
    err << name_of(o.names, "command") << ": noise terms written to " << o.calibration_path << "\n";
  AllanReport result;
  result.analysis = std::move(analysis).value();
  result.calibration_updated = out->cal != nullptr;
  return result;
}

}  // namespace tetra::report
