// Reading the attitude and truth files of `tetra score` (attitude_score.hpp).
#include <cmath>
#include <optional>
#include <string>

#include "tetra/core/attitude_score.hpp"
#include "tetra/core/csv.hpp"

namespace tetra {

namespace {

constexpr double kQuaternionNormTolerance =
    1e-3;  // files carry ≥ 6 digits; a larger departure is not a quaternion

Result<std::size_t> require_column(const CsvTable& t, const char* name) {
  if (auto c = t.find_column(name)) return *c;
  return bad_input(t.source + ":" + std::to_string(t.header_line) + ": header: no column '" + name + "'");
}

//! The finite value of a required cell, or bad input naming the cell.
Result<double> finite_cell(const CsvTable& t, std::size_t row, std::size_t col) {
  if (t.is_empty(row, col)) return bad_input(t.where(row, col) + "empty");
  const double v = t.cell(row, col);
  if (!std::isfinite(v)) return bad_input(t.where(row, col) + "not a finite number");
  return v;
}

//! A sigma cell: NaN means "not stated"; negative or infinite is bad input.
Result<double> sigma_cell(const CsvTable& t, std::size_t row, std::size_t col) {
  if (t.is_empty(row, col)) return bad_input(t.where(row, col) + "empty");
  const double v = t.cell(row, col);
  if (std::isnan(v)) return v;
  if (!std::isfinite(v) || v < 0.0) return bad_input(t.where(row, col) + "a 1σ must be a number ≥ 0");
  return v;
}

struct ScoreColumns {
  std::size_t time = 0;
  std::array<std::size_t, 4> q{};
  std::array<std::size_t, 3> rate{};
  std::optional<std::size_t> sigma;
  std::optional<std::array<std::size_t, 3>> sigma_axis;
};

Result<ScoreColumns> find_columns(const CsvTable& t, bool with_sigma) {
  ScoreColumns c;
  const char* q_names[4] = {"qw", "qx", "qy", "qz"};
  const char* rate_names[3] = {"wx_dps", "wy_dps", "wz_dps"};
  auto time = require_column(t, "time_s");
  if (!time) return time.error();
  c.time = *time;
  for (std::size_t k = 0; k < 4; ++k) {
    auto col = require_column(t, q_names[k]);
    if (!col) return col.error();
    c.q[k] = *col;
  }
  for (std::size_t k = 0; k < 3; ++k) {
    auto col = require_column(t, rate_names[k]);
    if (!col) return col.error();
    c.rate[k] = *col;
  }
  if (!with_sigma) return c;
  auto sigma = require_column(t, "sigma_deg");
  if (!sigma) return sigma.error();
  c.sigma = *sigma;
  const auto sx = t.find_column("sigma_x_deg");
  const auto sy = t.find_column("sigma_y_deg");
  const auto sz = t.find_column("sigma_z_deg");
  if (sx && sy && sz) c.sigma_axis = std::array<std::size_t, 3>{*sx, *sy, *sz};
  return c;
}

Status read_row(const CsvTable& t, const ScoreColumns& c, std::size_t r, AttitudeSeries& s) {
  auto time = finite_cell(t, r, c.time);
  if (!time) return time.error();
  if (!s.time_s.empty() && !(*time > s.time_s.back())) {
    return bad_input(t.where(r, c.time) + "time not increasing (previous row " +
                     std::to_string(s.lines.back()) + ")");
  }
  std::array<double, 4> q{};
  for (std::size_t k = 0; k < 4; ++k) {
    auto v = finite_cell(t, r, c.q[k]);
    if (!v) return v.error();
    q[k] = *v;
  }
  const Quaternion quat = from_wxyz(q);
  if (std::abs(quat.norm() - 1.0) > kQuaternionNormTolerance) {
    return bad_input(t.where(r, c.q[0]) + "quaternion norm " + std::to_string(quat.norm()) +
                     " is not 1 (within 1e-3)");
  }
  Eigen::Vector3d rate;
  for (std::size_t k = 0; k < 3; ++k) {
    auto v = finite_cell(t, r, c.rate[k]);
    if (!v) return v.error();
    rate(static_cast<Eigen::Index>(k)) = *v;
  }
  if (c.sigma) {
    auto v = sigma_cell(t, r, *c.sigma);
    if (!v) return v.error();
    s.sigma_deg.push_back(*v);
  }
  if (c.sigma_axis) {
    Eigen::Vector3d sigma;
    for (std::size_t k = 0; k < 3; ++k) {
      auto v = sigma_cell(t, r, (*c.sigma_axis)[k]);
      if (!v) return v.error();
      sigma(static_cast<Eigen::Index>(k)) = *v;
    }
    s.sigma_B_deg.push_back(sigma);
  }
  s.time_s.push_back(*time);
  s.q_RB.push_back(quat.normalized());
  s.rate_B_dps.push_back(rate);
  s.lines.push_back(t.lines[r]);
  return ok_status();
}

}  // namespace

Result<AttitudeSeries> parse_attitude_series(std::string_view text, const std::string& source,
                                             bool with_sigma) {
  auto table = parse_csv(text, source, {"mode", "gyros"});
  if (!table) return table.error();
  const CsvTable& t = *table;
  auto columns = find_columns(t, with_sigma);
  if (!columns) return columns.error();
  if (t.rows == 0) return bad_input(source + ": no rows");
  AttitudeSeries s;
  s.source = source;
  for (std::size_t r = 0; r < t.rows; ++r) {
    if (Status st = read_row(t, *columns, r, s); !st) return st.error();
  }
  return s;
}

Result<AttitudeSeries> read_attitude_series(const std::string& path, bool with_sigma) {
  auto text = read_text_file(path);
  if (!text) return text.error();
  return parse_attitude_series(*text, path, with_sigma);
}

}  // namespace tetra
