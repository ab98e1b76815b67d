#include "tetra/report/pointing_plot.hpp"

#include "tetra/core/csv.hpp"
#include "tetra/report/gnuplot.hpp"

namespace tetra::report {

namespace {

std::string num(double v) {
  std::string s;
  append_double(s, v);
  return s;
}

// time, error, estimated error, speeds..., torques...; decimated to at most ~20000 rows.
std::string series_data(const sim::ClosedLoopRecord& record) {
  std::string data;
  const std::size_t step = record.series.size() / 20000 + 1;
  for (std::size_t i = 0; i < record.series.size(); i += step) {
    const sim::PointingSample& s = record.series[i];
    data += num(s.time_s) + ' ' + num(s.error_deg) + ' ' + num(s.estimated_error_deg);
    for (Eigen::Index w = 0; w < s.wheel_speed_rpm.size(); ++w) data += ' ' + num(s.wheel_speed_rpm[w]);
    for (Eigen::Index w = 0; w < s.wheel_torque_Nm.size(); ++w) data += ' ' + num(s.wheel_torque_Nm[w]);
    data += '\n';
  }
  return data;
}

}  // namespace

Status plot_pointing(const std::string& png_path, const std::vector<PlottedRun>& runs, double bound_deg,
                     const std::vector<double>& onsets_s, const std::string& title) {
  if (runs.empty() || runs.front().record->series.empty())
    return failure(ErrorSubject(kPlotSubject), "nothing to plot");
  auto dir = TempDir::create("tetra-pointing");
  if (!dir) return failure(ErrorSubject(kPlotSubject), dir.error().message);
  std::vector<std::string> files;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    files.push_back((dir->path() / ("run" + std::to_string(r) + ".dat")).string());
    if (Status s = write_text_file(files.back(), series_data(*runs[r].record)); !s) return s;
  }
  const auto wheels = static_cast<int>(runs.front().record->series.front().wheel_speed_rpm.size());
  std::string body = "set datafile missing 'nan'\nset grid lc rgb '#dddddd'\nset key top left font ',9'\n";
  std::string escaped;  // enhanced text: '_' would start a subscript
  for (const char c : title) escaped += c == '_' ? std::string("\\_") : std::string(1, c);
  body += "set multiplot layout 3,1 title " + gp_quote(escaped) + "\n";
  for (double t : onsets_s) {
    body +=
        "set arrow from " + num(t) + ", graph 0 to " + num(t) + ", graph 1 nohead dt 3 lc rgb '#d62728'\n";
  }
  body += "set ylabel 'pointing error [deg]'\nset logscale y\n";
  body += "plot " + num(bound_deg) + " with lines lw 2 dt 2 lc rgb 'black' title 'bound " + num(bound_deg) +
          " deg'";
  const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e"};
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const std::string color = colors[r % 4];
    body += ", \\\n  " + gp_quote(files[r]) + " using 1:2 with lines lw 1.5 lc rgb '" + color + "' title " +
            gp_quote(runs[r].label + ": truth vs commanded");
    body += ", \\\n  " + gp_quote(files[r]) + " using 1:3 with lines lw 1 dt 2 lc rgb '" + color +
            "' title " + gp_quote(runs[r].label + ": estimated");
  }
  body += "\nunset logscale y\nset ylabel 'wheel speed [rpm]'\nplot ";
  for (int w = 0; w < wheels; ++w) {
    body += (w ? ", " : "") + gp_quote(files[0]) + " using 1:" + std::to_string(4 + w) +
            " with lines title 'wheel " + std::to_string(w + 1) + "'";
  }
  body += "\nset xlabel 'time [s]'\nset ylabel 'wheel torque [N m]'\nplot ";
  for (int w = 0; w < wheels; ++w) {
    body += (w ? ", " : "") + gp_quote(files[0]) + " using 1:" + std::to_string(4 + wheels + w) +
            " with lines title 'wheel " + std::to_string(w + 1) + "'";
  }
  body += "\nunset multiplot\n";
  return run_gnuplot(dir->path(), png_path, 1100, 1000, body, kPlotSubject);
}

}  // namespace tetra::report
