#include "tetra/core/allan_kalibr.hpp"

#include <cmath>
#include <optional>

#include <yaml-cpp/yaml.h>

#include "tetra/core/rate_covariance.hpp"
#include "tetra/core/units.hpp"

namespace tetra::allan {

namespace {

//! Largest body-axis value of a white (or random-walk) term combined by least squares over gyros with
//! per-gyro values `x`: sqrt(max diag((Σ h hᵀ / x²)⁻¹)); nullopt if the axes do not span 3-D.
std::optional<double> body_axis_value(const std::vector<Eigen::Vector3d>& axes,
                                      const std::vector<double>& x) {
  const auto covariance = least_squares_rate_covariance(axes, x);
  if (!covariance) return std::nullopt;
  return std::sqrt(covariance->diagonal().maxCoeff());
}

const GyroCalibration* find_gyro(const Calibration& calibration, int id) {
  for (const auto& g : calibration.gyros) {
    if (g.id == id) return &g;
  }
  return nullptr;
}

}  // namespace

Result<KalibrGyroNoise> kalibr_gyro_noise(const LogAllan& analysis, const Calibration& calibration) {
  if (analysis.units != "deg/s") {
    return bad_input({kSubjectKalibr}, "needs rates in deg/s: a log in volts needs a calibration");
  }
  std::vector<Eigen::Vector3d> axes;
  std::vector<double> n_rad, k_rad;  // [rad/√s], [rad/s/√s]
  bool k_everywhere = true;
  for (const GyroAllan& g : analysis.gyros) {
    const GyroCalibration* cal = find_gyro(calibration, g.id);
    if (cal == nullptr)
      return bad_input({kSubjectKalibr}, "gyro " + std::to_string(g.id) + " is not in the calibration");
    const auto n = g.result.fit.reported(kN);
    if (!n) {
      return failure(
          {kSubjectKalibr},
          "gyro " + std::to_string(g.id) +
              ": angle random walk N not observed (the record's shortest averaging times do not show it)");
    }
    const auto k = g.result.fit.reported(kK);
    k_everywhere = k_everywhere && k.has_value();
    axes.push_back(cal->axis_B);
    n_rad.push_back(*n * kDegToRad);
    k_rad.push_back(k ? *k * kDegToRad : 0.0);
  }
  KalibrGyroNoise out;
  out.update_rate_hz = 1.0 / analysis.tau0_s;
  const auto density = body_axis_value(axes, n_rad);
  if (!density) return bad_input({kSubjectKalibr}, "the analysed gyros' axes do not span three dimensions");
  out.noise_density_rad_s_rtHz = *density;
  if (k_everywhere) out.random_walk_rad_s2_rtHz = body_axis_value(axes, k_rad);
  return out;
}

std::string format_kalibr(const KalibrGyroNoise& noise, const std::string& rostopic) {
  YAML::Emitter out;
  out.SetDoublePrecision(6);
  out << YAML::Comment("Kalibr IMU configuration written by tetra allan --kalibr (docs/allan.md)")
      << YAML::Newline;
  out << YAML::BeginMap;
  out << YAML::Key << "rostopic" << YAML::Value << rostopic;
  out << YAML::Key << "update_rate" << YAML::Value << noise.update_rate_hz << YAML::Comment("[Hz]");
  out << YAML::Key << "gyroscope_noise_density" << YAML::Value << noise.noise_density_rad_s_rtHz
      << YAML::Comment("[rad/s/sqrt(Hz)] continuous time, from N");
  if (noise.random_walk_rad_s2_rtHz) {
    out << YAML::Key << "gyroscope_random_walk" << YAML::Value << *noise.random_walk_rad_s2_rtHz
        << YAML::Comment("[rad/s^2/sqrt(Hz)] continuous time, from K");
  }
  out << YAML::EndMap;
  std::string text = out.c_str();
  text += "\n";
  if (!noise.random_walk_rad_s2_rtHz) {
    text +=
        "# gyroscope_random_walk: not observed (K needs a longer record); give an upper bound before using "
        "Kalibr\n";
  }
  text +=
      "# accelerometer_noise_density, accelerometer_random_walk [m/s^2/sqrt(Hz), m/s^3/sqrt(Hz)]: unknown, "
      "a\n"
      "# gyro-only unit measures no acceleration; Kalibr needs them: add your accelerometer's values\n";
  return text;
}

}  // namespace tetra::allan
