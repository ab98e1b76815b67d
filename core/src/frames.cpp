#include "tetra/core/frames.hpp"

#include <cmath>

#include "tetra/core/units.hpp"

namespace tetra {

Eigen::Vector3d earth_rate_L(double latitude_rad) {
  return kEarthRate_rad_s * Eigen::Vector3d(std::sin(latitude_rad), 0.0, std::cos(latitude_rad));
}

Eigen::Matrix3d rotation_x(double angle_rad) {
  const double c = std::cos(angle_rad);
  const double s = std::sin(angle_rad);
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}

Eigen::Matrix3d rotation_y(double angle_rad) {
  const double c = std::cos(angle_rad);
  const double s = std::sin(angle_rad);
  Eigen::Matrix3d r;
  r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}

Eigen::Matrix3d turntable_C_LB(double inner_rad, double outer_rad) {
  return rotation_y(outer_rad) * rotation_x(inner_rad);
}

Eigen::Vector3d turntable_rate_B(double inner_rad, double inner_dot_rad_s, double outer_dot_rad_s) {
  return {inner_dot_rad_s, outer_dot_rad_s * std::cos(inner_rad), -outer_dot_rad_s * std::sin(inner_rad)};
}

Eigen::Vector3d turntable_earth_rate_B(double inner_rad, double outer_rad, double latitude_rad) {
  return turntable_C_LB(inner_rad, outer_rad).transpose() * earth_rate_L(latitude_rad);
}

}  // namespace tetra
