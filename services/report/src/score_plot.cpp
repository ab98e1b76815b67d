#include "tetra/report/score_plot.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/report/gnuplot.hpp"

namespace tetra::report {

namespace {

struct Scale {
  double per_deg = 1.0;  // plotted value = deg · per_deg
  const char* unit = "deg";
};

//! arcsec when the error and its 3σ stay below 0.05°, else deg.
Scale error_scale(const AttitudeScore& score) {
  double largest_deg = score.max_total_deg;
  for (const ScoredEpoch& e : score.epochs) {
    const double s = score.per_axis_sigma ? e.sigma_B_deg.maxCoeff() : e.sigma_deg;
    if (std::isfinite(s)) largest_deg = std::max(largest_deg, 3.0 * s);
  }
  return largest_deg < 0.05 ? Scale{3600.0, "arcsec"} : Scale{1.0, "deg"};
}

// time, e_x, e_y, e_z, 3σ_x, 3σ_y, 3σ_z (the total σ when there are no per-axis columns); at most ~20000
// rows.
std::string series_data(const AttitudeScore& score, const Scale& scale, double time_per_s) {
  std::string data;
  const std::size_t step = score.epochs.size() / 20000 + 1;
  for (std::size_t i = 0; i < score.epochs.size(); i += step) {
    const ScoredEpoch& e = score.epochs[i];
    append_double(data, e.time_s * time_per_s);
    for (int k = 0; k < 3; ++k) {
      data += ' ';
      append_double(data, e.error_B_deg(k) * scale.per_deg);
    }
    for (int k = 0; k < 3; ++k) {
      const double sigma = score.per_axis_sigma ? e.sigma_B_deg(k) : e.sigma_deg;
      data += ' ';
      append_double(data, 3.0 * sigma * scale.per_deg);
    }
    data += '\n';
  }
  return data;
}

}  // namespace

Status write_score_plot(OutputFile& png, const AttitudeScore& score, const std::string& title) {
  auto temp = TempDir::create("tetra-score");
  if (!temp) return failure(ErrorSubject(kPlotSubject), temp.error().message);
  const std::filesystem::path& dir = temp->path();
  const Scale scale = error_scale(score);
  const bool minutes = score.epochs.back().time_s - score.epochs.front().time_s > 1200.0;
  const std::string data_file = (dir / "error.dat").string();
  if (Status s = write_text_file(data_file, series_data(score, scale, minutes ? 1.0 / 60.0 : 1.0)); !s)
    return s;

  std::string escaped;  // enhanced text: '_' would start a subscript
  for (const char c : title) escaped += c == '_' ? std::string("\\_") : std::string(1, c);
  const std::string envelope = score.per_axis_sigma ? "±3σ (axis)" : "±3σ (total sigma\\_deg)";
  std::string body = "set datafile missing 'nan'\nset grid lc rgb '#dddddd'\nset key top left font ',9'\n";
  body += "set multiplot layout 3,1 title " + gp_quote(escaped) + "\n";
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    const std::string e_col = std::to_string(2 + k);
    const std::string s_col = std::to_string(5 + k);
    if (k == 2) body += std::string("set xlabel 'time [") + (minutes ? "min" : "s") + "]'\n";
    body += "set ylabel " + gp_quote(std::string("error about ") + axes[k] + " [" + scale.unit + "]") + "\n";
    body += "plot " + gp_quote(data_file) + " using 1:" + s_col +
            " with lines lw 1.5 dt 2 lc rgb 'black' title " + gp_quote(envelope) + ", \\\n  " +
            gp_quote(data_file) + " using 1:(-$" + s_col +
            ") with lines lw 1.5 dt 2 lc rgb 'black' notitle, \\\n  " + gp_quote(data_file) +
            " using 1:" + e_col + " with lines lw 1 lc rgb '#1f77b4' title 'estimate − truth'\n";
  }
  body += "unset multiplot\n";
  // gnuplot writes into the temporary directory; the image reaches --plot through the output layer.
  const std::string png_path = (dir / "plot.png").string();
  if (Status s = run_gnuplot(dir, png_path, 1000, 900, body, kPlotSubject); !s) return s;
  auto image = read_input(png_path, kMaxTableBytes);
  if (!image) return failure(ErrorSubject(kPlotSubject), "gnuplot wrote no image");
  return png.write(*image);
}

}  // namespace tetra::report
