#pragma once
// Attitude propagation from body rates, with a per-axis uncertainty.
//
//   q_RB ← q_RB ⊗ exp(½ ω Δt)   (exact exponential map, quaternion.hpp); in ground mode (R = the lab L, which
//   turns with the Earth) q_LB ← exp(−½ ω_e^L Δt) ⊗ q_LB ⊗ exp(½ ω_B Δt): exact for the measured rate ω_B
//   constant in B and the Earth rate ω_e^L constant in L over the step. The published rate relative to L is
//   ω_B − ω_e^B, with ω_e^B = C_BL·ω_e^L the Earth rate seen in B at the current attitude.
//
// Uncertainty per body axis a, three independent parts added in quadrature:
//   random:     σ²_rand,a += N²_a·Δt          (white rate noise N_a [rad/√s]: grows with √t)
//   systematic: σ_sys,a   += b_a·Δt           (1σ rate bias left by the calibration [rad/s]: grows with t)
//   bound:      σ_bnd,a   += e_a·Δt           (rate error bound of an unresolved fault [rad/s], added
//   linearly) σ_a = √(σ²_rand,a + σ²_sys,a + σ²_bnd,a).
// The bound is an angle error already made: it turns with the body. It is kept as a box in the body axes
// of the attitude where it began (B0) and read in the current ones through |C_B0B|, the rotation's
// element-wise magnitude (the smallest box about the turned one); what a step adds in the current axes
// enters B0's the same way. A slew after a fault moves the error from one body axis to another, and the
// bound with it.

#include <optional>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"

namespace tetra {

class AttitudePropagator {
 public:
  //! `latitude_rad` set: ground-test mode (Earth rate removed); q0: initial attitude (relative to L then).
  AttitudePropagator(const Quaternion& q0_RB, std::optional<double> latitude_rad);

  void reset(const Quaternion& q0_RB);
  //! Turns the attitude by `dq_B` in B (q_RB ← q_RB ⊗ dq_B, normalized), e.g. a filter's correction; the
  //! uncertainty is kept.
  void rotate(const Quaternion& dq_B) { q_RB_ = (q_RB_ * dq_B).normalized(); }

  //! [rad/s] Earth rate in B at the current attitude; zero outside ground-test mode.
  Eigen::Vector3d earth_rate_B() const;

  //! One step with the measured body rate (which includes the Earth rate on the ground).
  //! `arw_sq_rad2_s` [rad²/s]: N² per axis; `bias_sigma_rad_s`, `bound_rad_s` [rad/s] per axis.
  //! Returns the rate used for propagation (Earth rate removed in ground mode).
  Eigen::Vector3d step(const Eigen::Vector3d& omega_meas_B_rad_s, double dt_s,
                       const Eigen::Vector3d& arw_sq_rad2_s, const Eigen::Vector3d& bias_sigma_rad_s,
                       const Eigen::Vector3d& bound_rad_s);

  //! Adds an angle bound [rad] per axis at once (e.g. the error a fault caused before it was isolated).
  void add_bound(const Eigen::Vector3d& angle_rad);

  const Quaternion& q_RB() const { return q_RB_; }
  //! The last step's body rotation exp(½ ω_B Δt) (ω_B the rate the step turned B by: the measured rate in
  //! ground mode, the rate relative to R otherwise); identity before any step.
  const Quaternion& last_increment() const { return increment_; }
  //! [rad] 1σ per body axis.
  Eigen::Vector3d sigma_rad() const;

 private:
  Quaternion q_RB_;                                 //!< body → reference (L in ground mode); unit norm
  Quaternion increment_ = Quaternion::Identity();   //!< the last step's body rotation
  std::optional<Eigen::Vector3d> earth_rate_L_;     //!< [rad/s] set in ground-test mode
  Eigen::Vector3d var_random_rad2_;                 //!< [rad²]
  Eigen::Vector3d systematic_rad_;                  //!< [rad]
  Eigen::Vector3d bound_rad_;                       //!< [rad] in the body axes of `bound_q_RB_`
  Quaternion bound_q_RB_ = Quaternion::Identity();  //!< the attitude where the bound began (B0)
  //! [-] |C_B0B|: a box in the current body axes, as one in B0's
  Eigen::Matrix3d to_bound_axes() const;
};

}  // namespace tetra
