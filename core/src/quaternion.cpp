#include "tetra/core/quaternion.hpp"

#include <algorithm>
#include <cmath>

namespace tetra {

Quaternion quat_exp(const Eigen::Vector3d& rotvec_rad) {
  const double angle = rotvec_rad.norm();
  const double half = 0.5 * angle;
  double w = 0.0;
  double k = 0.0;  // sin(half)/angle
  if (angle < 1e-4) {
    // Series to O(angle^6): relative error far below 1e-16 in this range.
    const double a2 = angle * angle;
    w = 1.0 - a2 / 8.0 + a2 * a2 / 384.0;
    k = 0.5 - a2 / 48.0 + a2 * a2 / 3840.0;
  } else {
    w = std::cos(half);
    k = std::sin(half) / angle;
  }
  Quaternion q(w, k * rotvec_rad.x(), k * rotvec_rad.y(), k * rotvec_rad.z());
  return q.normalized();
}

Eigen::Vector3d quat_log(const Quaternion& q_in) {
  const Quaternion q = canonical(q_in);
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-8) {
    // angle = 2·atan2(s, w) ≈ 2 s / w (1 − s²/(3w²)); factor angle/s.
    const double w = q.w();
    return (2.0 / w - 2.0 * s * s / (3.0 * w * w * w)) * v;
  }
  const double angle = 2.0 * std::atan2(s, q.w());
  return (angle / s) * v;
}

Quaternion propagate(const Quaternion& q_RB, const Eigen::Vector3d& omega_BR_B_rad_s, double dt_s) {
  return (q_RB * quat_exp(omega_BR_B_rad_s * dt_s)).normalized();
}

double angle_between(const Quaternion& a, const Quaternion& b) {
  return quat_log(a.conjugate() * b).norm();
}

Quaternion canonical(const Quaternion& q) {
  Quaternion n = q.normalized();
  if (n.w() < 0.0) n.coeffs() = -n.coeffs();
  return n;
}

}  // namespace tetra
