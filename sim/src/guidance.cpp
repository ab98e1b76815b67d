#include "tetra/sim/guidance.hpp"

#include <algorithm>
#include <cmath>

#include "tetra/core/units.hpp"
#include "tetra/sim/dynamics.hpp"

namespace tetra::sim {

double trapezoid_duration_s(double total_rad, double max_rate_rad_s, double max_accel_rad_s2) {
  const double angle = std::abs(total_rad);
  const double w_peak = std::min(max_rate_rad_s, std::sqrt(angle * max_accel_rad_s2));
  if (w_peak <= 0.0) return 0.0;
  const double t_acc = w_peak / max_accel_rad_s2;
  const double coast_angle = angle - w_peak * t_acc;
  return 2.0 * t_acc + coast_angle / w_peak;
}

SlewProfile trapezoid_profile(double total_rad, double max_rate_rad_s, double max_accel_rad_s2, double u_s) {
  const double angle = std::abs(total_rad);
  const double sign = total_rad < 0.0 ? -1.0 : 1.0;
  const double w_peak = std::min(max_rate_rad_s, std::sqrt(angle * max_accel_rad_s2));
  SlewProfile p;
  if (w_peak <= 0.0 || u_s <= 0.0) return p;
  const double a = max_accel_rad_s2;
  const double t_acc = w_peak / a;
  const double t_total = trapezoid_duration_s(angle, max_rate_rad_s, a);
  if (u_s >= t_total) {
    p.angle_rad = angle;
  } else if (u_s < t_acc) {
    p = {0.5 * a * u_s * u_s, a * u_s, a};
  } else if (u_s < t_total - t_acc) {
    p = {0.5 * a * t_acc * t_acc + w_peak * (u_s - t_acc), w_peak, 0.0};
  } else {
    const double left = t_total - u_s;
    p = {angle - 0.5 * a * left * left, a * left, -a};
  }
  p.angle_rad *= sign;
  p.rate_rad_s *= sign;
  p.accel_rad_s2 *= sign;
  return p;
}

Guidance::Guidance(const PointingSpec& spec, double orbit_rate_rad_s)
    : spec_(spec), orbit_rate_rad_s_(orbit_rate_rad_s) {}

PointingReference Guidance::at(double t_s) const {
  const bool nadir = spec_.mode == PointingMode::kNadir;
  const Quaternion q_NO = nadir ? orbit_frame_q_NO(orbit_rate_rad_s_, t_s) : spec_.q_NR0;
  const Eigen::Vector3d omega_ON_O(0.0, nadir ? -orbit_rate_rad_s_ : 0.0, 0.0);
  const double w_max = spec_.max_rate_dps * kDegToRad;
  const double a_max = spec_.max_accel_dps2 * kDegToRad;
  Quaternion q_OR = Quaternion::Identity();
  Eigen::Vector3d slew_rate_R = Eigen::Vector3d::Zero();
  Eigen::Vector3d slew_accel_R = Eigen::Vector3d::Zero();
  for (const PointingSlew& slew : spec_.slews) {
    if (t_s <= slew.start_s) break;
    const SlewProfile p = trapezoid_profile(slew.angle_deg * kDegToRad, w_max, a_max, t_s - slew.start_s);
    q_OR = q_OR * quat_exp(p.angle_rad * slew.axis_R);
    slew_rate_R = p.rate_rad_s * slew.axis_R;
    slew_accel_R = p.accel_rad_s2 * slew.axis_R;
  }
  PointingReference ref;
  ref.q_NR = canonical(q_NO * q_OR);
  const Eigen::Vector3d omega_ON_R = q_OR.conjugate() * omega_ON_O;
  ref.omega_RN_R_rad_s = omega_ON_R + slew_rate_R;
  ref.alpha_RN_R_rad_s2 = -slew_rate_R.cross(omega_ON_R) + slew_accel_R;
  return ref;
}

}  // namespace tetra::sim
