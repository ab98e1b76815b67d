#include "tetra/report/attitude_csv.hpp"

#include <algorithm>
#include <cstring>

#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"  // kRadToDeg

namespace tetra::report {

namespace {

char* put(char* p, std::string_view text) {
  std::memcpy(p, text.data(), text.size());
  return p + text.size();
}

char* put_double(char* p, double value) {
  *p++ = ',';
  return format_double(p, value);
}

// The longest mode name to_string(Mode) gives.
std::size_t longest_mode_chars() {
  std::size_t longest = 0;
  for (const auto mode : {fdi::Mode::kNominal, fdi::Mode::kDegraded, fdi::Mode::kSuspect, fdi::Mode::kLost})
    longest = std::max(longest, std::strlen(fdi::to_string(mode)));
  return longest;
}

}  // namespace

std::size_t attitude_row_max_bytes(int n_gyros) {
  const auto n = static_cast<std::size_t>(std::max(n_gyros, 0));
  // time, q (4), rate (3), sigma, sigma per axis (3), biases, protection level per axis (3)
  const std::size_t numbers = 15 + n;
  const std::size_t gyros_cell_chars = 3 * n;  // at most two digits and a ';' per gyro
  return numbers * (kMaxDoubleChars + 1) + longest_mode_chars() + 1 + gyros_cell_chars + 1;
}

char* format_attitude_row(char* out, double time_s, const fdi::AttitudeEstimate& attitude,
                          std::span<const double> bias_rad_s, int n_gyros, std::string_view gyros) {
  char* p = format_double(out, time_s);
  for (const double c : to_wxyz(attitude.q_RB)) p = put_double(p, c);
  for (int i = 0; i < 3; ++i) p = put_double(p, attitude.omega_BR_B_rad_s[i] * kRadToDeg);
  p = put_double(p, attitude.sigma_rad.norm() * kRadToDeg);  // 1σ of the total error angle
  *p++ = ',';
  p = put(p, fdi::to_string(attitude.mode));
  *p++ = ',';
  p = put(p, gyros);
  for (int i = 0; i < 3; ++i) p = put_double(p, attitude.sigma_rad[i] * kRadToDeg);
  const bool biases = static_cast<int>(bias_rad_s.size()) == n_gyros;
  for (int i = 0; i < n_gyros; ++i) {
    if (biases) {
      p = put_double(p, bias_rad_s[static_cast<std::size_t>(i)] * kRadToDeg);
    } else {
      p = put(p, ",nan");
    }
  }
  for (int i = 0; i < 3; ++i) p = put_double(p, attitude.protection_level_rad[i] * kRadToDeg);
  *p++ = '\n';
  return p;
}

void append_attitude_row(std::string& out, double time_s, const fdi::AttitudeEstimate& attitude,
                         int n_gyros) {
  const std::size_t start = out.size();
  out.resize(start + attitude_row_max_bytes(n_gyros));
  const std::string cell = gyros_cell(attitude.gyros, n_gyros);
  char* end =
      format_attitude_row(out.data() + start, time_s, attitude, attitude.gyro_bias_rad_s, n_gyros, cell);
  out.resize(static_cast<std::size_t>(end - out.data()));
}

std::string attitude_header(int n_gyros) {
  std::string h =
      "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros,sigma_x_deg,sigma_y_deg,sigma_z_deg";
  for (int i = 1; i <= n_gyros; ++i) h += ",bias_" + std::to_string(i) + "_dps";
  return h + ",pl_x_deg,pl_y_deg,pl_z_deg\n";
}

std::string gyros_cell(GyroMask mask, int n_gyros) {
  std::string cell = mask_to_string(mask, n_gyros);  // "1234"; "1,2,10" from 10 gyros on
  for (char& c : cell) {
    if (c == ',') c = ';';  // one CSV field for any N: "1;2;10"
  }
  return cell;
}

const std::string& GyrosCellCache::cell(GyroMask mask) {
  if (!valid_ || mask != mask_) {
    cell_ = gyros_cell(mask, n_gyros_);
    mask_ = mask;
    valid_ = true;
  }
  return cell_;
}

}  // namespace tetra::report
