#pragma once
// The noise of a gyro package as Kalibr's IMU configuration (imu.yaml), for camera/IMU calibration
// tools that read it (docs/allan.md, "Kalibr"). Kalibr models one 3-axis gyro with the same continuous-
// time white noise and random walk on each axis; tetra's body rate is the weighted least-squares
// combination of N single-axis gyros, so each body axis gets its own value and the largest is reported.

#include <string>

#include "tetra/core/allan.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/result.hpp"

namespace tetra::allan {

struct KalibrGyroNoise {
  double noise_density_rad_s_rtHz = 0.0;          //!< gyroscope_noise_density [rad/s/√Hz] (from N)
  std::optional<double> random_walk_rad_s2_rtHz;  //!< gyroscope_random_walk [rad/s²/√Hz] (from K); nullopt:
                                                  //!< K not observed on every gyro analysed
  double update_rate_hz = 0.0;  //!< 1/τ0
};

//! Body-axis noise of the analysed gyros (deg/s units required; axes from `calibration`):
//! σ_axis² = max over axes of diag((Σ_i h_i h_iᵀ / X_i²)⁻¹) for X = N and X = K. Errors: volts, fewer than
//! 3 gyros or axes not spanning 3-D, N not observed on a gyro.
Result<KalibrGyroNoise> kalibr_gyro_noise(const LogAllan& analysis, const Calibration& calibration);

//! imu.yaml text: rostopic, update_rate, gyroscope_noise_density, gyroscope_random_walk; the
//! accelerometer keys, which a gyro-only unit cannot know, and an unobserved random walk, are commented out.
std::string format_kalibr(const KalibrGyroNoise& noise, const std::string& rostopic);

}  // namespace tetra::allan
