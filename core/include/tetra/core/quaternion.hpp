#pragma once
// Attitude quaternion convention — the only place tetra defines or converts it (docs/interfaces.md §1):
//   * Hamilton product, scalar first in files and on the wire: (w, x, y, z);
//   * q_RB maps body → reference: v_R = q ⊗ v_B ⊗ q*  (Eigen: v_R = q * v_B, q.toRotationMatrix() = C_RB);
//   * propagation with the body rate ω_B over Δt: q ← q ⊗ exp(½ ω_B Δt), exp of the rotation vector
//     ω_B Δt computed exactly (with a small-angle series near zero).
// Eigen::Quaterniond is Hamilton; its constructor takes (w, x, y, z) but its storage is (x, y, z, w):
// never memcpy it, use from_wxyz()/to_wxyz().
// Invariant: every quaternion returned here has unit norm and w ≥ 0 where stated.

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tetra {

using Quaternion = Eigen::Quaterniond;

//! Quaternion from scalar-first components (not normalized).
inline Quaternion from_wxyz(double w, double x, double y, double z) {
  return Quaternion(w, x, y, z);
}
inline Quaternion from_wxyz(const std::array<double, 4>& q) {
  return Quaternion(q[0], q[1], q[2], q[3]);
}
//! Scalar-first components.
inline std::array<double, 4> to_wxyz(const Quaternion& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}

//! exp of a rotation vector [rad]: the unit quaternion of a rotation by |rotvec| about rotvec/|rotvec|.
Quaternion quat_exp(const Eigen::Vector3d& rotvec_rad);

//! log of a unit quaternion: rotation vector [rad] with angle in [0, π]. Sign of q is irrelevant.
Eigen::Vector3d quat_log(const Quaternion& q);

//! One exact propagation step: q_RB(t+Δt) = q_RB(t) ⊗ exp(ω_B Δt), renormalized.
Quaternion propagate(const Quaternion& q_RB, const Eigen::Vector3d& omega_BR_B_rad_s, double dt_s);

//! [rad] Angle of the rotation between two attitudes, in [0, π].
double angle_between(const Quaternion& a, const Quaternion& b);

//! Canonical sign (w ≥ 0), normalized.
Quaternion canonical(const Quaternion& q);

}  // namespace tetra
