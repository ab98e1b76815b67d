#pragma once
// Pointing guidance: the commanded attitude q_NR(t), rate ω_RN_R and angular acceleration α_RN_R.
//
//   q_NR(t) = q_NO(t) ⊗ q_OR(t)        nadir: O the orbit frame (ω_ON_O = (0, −n, 0));
//                                      inertial: O fixed at the target q_NR0 (ω_ON_O = 0)
//   q_OR(t) = exp(Φ₁e₁) ⊗ … ⊗ exp(φ_k(t)·e_k)   the slews done and the one under way
//   ω_RN_R  = C_RO·ω_ON_O + φ̇_k·e_k
//   α_RN_R  = −(φ̇_k·e_k) × (C_RO·ω_ON_O) + φ̈_k·e_k
// Each slew follows a trapezoidal rate profile: acceleration a_max up to the rate limit w_max (or a
// triangle when the angle is shorter than w_max²/a_max), coast, and deceleration to rest.

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/sim/closed_loop_spec.hpp"

namespace tetra::sim {

struct PointingReference {
  Quaternion q_NR = Quaternion::Identity();
  Eigen::Vector3d omega_RN_R_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d alpha_RN_R_rad_s2 = Eigen::Vector3d::Zero();
};

//! Angle, rate and acceleration of a rest-to-rest trapezoidal profile at time `u_s` after its start.
struct SlewProfile {
  double angle_rad = 0.0;
  double rate_rad_s = 0.0;
  double accel_rad_s2 = 0.0;
};
SlewProfile trapezoid_profile(double total_rad, double max_rate_rad_s, double max_accel_rad_s2, double u_s);
//! [s] duration of that profile.
double trapezoid_duration_s(double total_rad, double max_rate_rad_s, double max_accel_rad_s2);

class Guidance {
 public:
  Guidance(const PointingSpec& spec, double orbit_rate_rad_s);
  PointingReference at(double t_s) const;

 private:
  PointingSpec spec_;
  double orbit_rate_rad_s_;
};

}  // namespace tetra::sim
