#include "attitude_csv.hpp"

#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"  // kRadToDeg

namespace tetra::cli {

void append_attitude_row(std::string& out, double time_s, const fdi::AttitudeEstimate& attitude,
                         int n_gyros) {
  append_double(out, time_s);
  for (const double c : to_wxyz(attitude.q_RB)) {
    out += ',';
    append_double(out, c);
  }
  for (int i = 0; i < 3; ++i) {
    out += ',';
    append_double(out, attitude.omega_BR_B_rad_s[i] * kRadToDeg);
  }
  out += ',';
  append_double(out, attitude.sigma_rad.norm() * kRadToDeg);  // 1σ of the total error angle
  out += ',';
  out += fdi::to_string(attitude.mode);
  out += ',';
  out += gyros_cell(attitude.gyros, n_gyros);
  for (int i = 0; i < 3; ++i) {
    out += ',';
    append_double(out, attitude.sigma_rad[i] * kRadToDeg);
  }
  const bool biases = static_cast<int>(attitude.gyro_bias_rad_s.size()) == n_gyros;
  for (int i = 0; i < n_gyros; ++i) {
    out += ',';
    if (biases) {
      append_double(out, attitude.gyro_bias_rad_s[static_cast<std::size_t>(i)] * kRadToDeg);
    } else {
      out += "nan";
    }
  }
  out += '\n';
}

std::string attitude_header(int n_gyros) {
  std::string h =
      "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros,sigma_x_deg,sigma_y_deg,sigma_z_deg";
  for (int i = 1; i <= n_gyros; ++i) h += ",bias_" + std::to_string(i) + "_dps";
  return h + "\n";
}

std::string gyros_cell(GyroMask mask, int n_gyros) {
  std::string cell = mask_to_string(mask, n_gyros);  // "1234"; "1,2,10" from 10 gyros on
  for (char& c : cell) {
    if (c == ',') c = ';';  // one CSV field for any N: "1;2;10"
  }
  return cell;
}

}  // namespace tetra::cli
