// Attitude rows (tetra/report/attitude_csv.hpp) as replay's writer formats them straight into its
// buffer: the same text as a row built cell by cell with append_double, within attitude_row_max_bytes for the
// widest numbers, and the gyros cell cached per mask.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"
#include "tetra/report/attitude_csv.hpp"

namespace tetra::report {
namespace {

fdi::AttitudeEstimate estimate(double x, int n_gyros, GyroMask mask) {
  fdi::AttitudeEstimate a;
  a.q_RB = Quaternion(0.5, -0.5, 0.5, x).normalized();
  a.omega_BR_B_rad_s = Eigen::Vector3d(x, -1e-300, 0.0);
  a.sigma_rad = Eigen::Vector3d(1e-7, std::numeric_limits<double>::quiet_NaN(), 3.0);
  a.mode = fdi::Mode::kDegraded;
  a.gyros = mask;
  for (int i = 0; i < n_gyros; ++i) a.gyro_bias_rad_s.push_back(x * (i + 1));
  a.protection_level_rad = Eigen::Vector3d(2e-7, x, std::numeric_limits<double>::infinity());
  return a;
}

// The row cell by cell, as the writer did before it formatted into its own buffer.
std::string row_cell_by_cell(double time_s, const fdi::AttitudeEstimate& a, int n_gyros) {
  std::string out;
  append_double(out, time_s);
  for (const double c : to_wxyz(a.q_RB)) {
    out += ',';
    append_double(out, c);
  }
  for (int i = 0; i < 3; ++i) {
    out += ',';
    append_double(out, a.omega_BR_B_rad_s[i] * kRadToDeg);
  }
  out += ',';
  append_double(out, a.sigma_rad.norm() * kRadToDeg);
  out += std::string(",") + fdi::to_string(a.mode) + "," + gyros_cell(a.gyros, n_gyros);
  for (int i = 0; i < 3; ++i) {
    out += ',';
    append_double(out, a.sigma_rad[i] * kRadToDeg);
  }
  const bool biases = static_cast<int>(a.gyro_bias_rad_s.size()) == n_gyros;
  for (int i = 0; i < n_gyros; ++i) {
    out += ',';
    if (biases) {
      append_double(out, a.gyro_bias_rad_s[static_cast<std::size_t>(i)] * kRadToDeg);
    } else {
      out += "nan";
    }
  }
  for (int i = 0; i < 3; ++i) {  // the protection level, after the biases
    out += ',';
    append_double(out, a.protection_level_rad[i] * kRadToDeg);
  }
  return out + "\n";
}

TEST(AttitudeCsv, RowIsTheCellByCellText) {
  for (const double x : {0.1, -2.5e-17, 1.0 / 3.0, 12345.678}) {
    std::string row = "head\n";
    append_attitude_row(row, 86400.01, estimate(x, 4, 0b1011), 4);
    EXPECT_EQ(row, "head\n" + row_cell_by_cell(86400.01, estimate(x, 4, 0b1011), 4));
  }
}

TEST(AttitudeCsv, TenGyrosAndMissingBiases) {
  fdi::AttitudeEstimate a = estimate(0.25, 3, (1u << 0) | (1u << 1) | (1u << 9));  // 3 biases, not 10
  std::string row;
  append_attitude_row(row, 1.5, a, 10);
  EXPECT_EQ(row, row_cell_by_cell(1.5, a, 10));
  EXPECT_NE(row.find(",1;2;10,"), std::string::npos) << row;
  EXPECT_NE(row.find(",nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,"), std::string::npos) << row;
  EXPECT_NE(row.find(",inf\n"), std::string::npos) << row;  // no protection level: no parity
}

// The widest double text is kMaxDoubleChars long; a row of 32 gyros of such numbers fits the bound.
TEST(AttitudeCsv, WidestRowFitsTheBound) {
  const double widest = -2.2250738585072014e-308;
  std::string text;
  append_double(text, widest);
  EXPECT_EQ(text.size(), kMaxDoubleChars);
  const int n = 32;
  fdi::AttitudeEstimate a;
  a.q_RB = Quaternion(widest, widest, widest, widest);  // not normalized: only the text matters here
  a.omega_BR_B_rad_s = Eigen::Vector3d::Constant(widest / kRadToDeg);
  a.sigma_rad = Eigen::Vector3d::Constant(-1.7976931348623157e308 / kRadToDeg);
  a.mode = fdi::Mode::kDegraded;
  a.gyros = 0xFFFFFFFFu;
  a.gyro_bias_rad_s.assign(n, widest / kRadToDeg);
  a.protection_level_rad = Eigen::Vector3d::Constant(widest / kRadToDeg);
  std::string row;
  append_attitude_row(row, widest, a, n);
  EXPECT_LE(row.size(), attitude_row_max_bytes(n));
  EXPECT_EQ(row, row_cell_by_cell(widest, a, n));
}

TEST(AttitudeCsv, GyrosCellCacheFollowsTheMask) {
  GyrosCellCache cache(4);
  EXPECT_EQ(cache.cell(0b1111), "1234");
  EXPECT_EQ(cache.cell(0b1111), "1234");
  EXPECT_EQ(cache.cell(0b0110), "23");
  EXPECT_EQ(cache.cell(0), "");
  EXPECT_EQ(cache.cell(0b1111), "1234");
  GyrosCellCache wide(12);
  EXPECT_EQ(wide.cell((1u << 0) | (1u << 11)), "1;12");
}

}  // namespace
}  // namespace tetra::report
