#pragma once
// The seed's as-built unit with N = 3…6 gyros, for tests and benchmarks that run the pipeline on more or
// fewer gyros than the tetrahedron (the golden trace, bench/fdi_sweep.cpp).

#include "tetra/core/calibration_file.hpp"

namespace tetra::test {

//! A gyro like `like`'s first, with its own id, scale factor, bias and axis.
inline GyroCalibration extra_gyro(int id, const Eigen::Vector3d& axis, const Calibration& like) {
  GyroCalibration g = like.gyros[0];
  g.id = id;
  g.scale_factor_V_per_dps = 0.08 + 0.001 * id;
  g.bias_V = 1e-4 * id;
  g.axis_B = axis.normalized();
  return g;
}

//! The seed's unit cut to its first three gyros (n = 3), as is (4), or with gyros 5 and 6 added (5, 6).
inline Calibration unit_with(int n) {
  Calibration cal = seed_as_built_unit();
  if (n == 3) cal.gyros.resize(3);
  if (n >= 5) cal.gyros.push_back(extra_gyro(5, Eigen::Vector3d(0.3, 0.5, -0.6), cal));
  if (n >= 6) cal.gyros.push_back(extra_gyro(6, Eigen::Vector3d(-0.4, 0.7, 0.2), cal));
  return cal;
}

}  // namespace tetra::test
