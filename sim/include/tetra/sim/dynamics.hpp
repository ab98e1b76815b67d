#pragma once
// Rigid-body attitude dynamics with reaction wheels (frames and names: closed_loop_spec.hpp).
//
//   q̇_NB  = ½ q_NB ⊗ (0, ω_BN_B)
//   I·ω̇   = τ_ext − G·τ_w − ω × (I·ω + G·h_w)      (Euler's equations with the wheels' momentum)
//   ḣ_w   = τ_w                                      (motor torque on each wheel, per wheel axis)
// G (3×n) holds the wheel spin axes in B; H_w_B = G·h_w. The external torque τ_ext is the sum of the
// disturbances (constant, orbital-periodic, gravity gradient 3n²·r̂ × I·r̂ with r̂ the zenith unit
// vector in B). Integrated by classic fixed-step RK4 (the quaternion renormalized after each step);
// the wheel torques are held over a control period (zero-order hold). The disturbance's terms that depend
// on time alone are computed once per distinct time (RK4's two midpoints share theirs, a step's end is the
// next one's start), G·τ_w once per advance() (the torques are held), and the wheel vectors live on the
// stack (no allocation per step).

#include <vector>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/sim/closed_loop_spec.hpp"

namespace tetra::sim {

struct BodyState {
  Quaternion q_NB = Quaternion::Identity();                    //!< B → N
  Eigen::Vector3d omega_BN_B_rad_s = Eigen::Vector3d::Zero();  //!< [rad/s]
  Eigen::VectorXd h_wheels_Nms;                                //!< [N·m·s] per wheel, along its axis
};

//! [-] 3×n wheel spin axes in B for `wheels` (3 along X, Y, Z; 4 in the pyramid).
Eigen::MatrixXd wheel_axes_B(const WheelSpec& wheels);

//! Orbit (LVLH) frame at time t: q_NO(t) = exp(−n·t·ŷ) (O = N at t = 0).
Quaternion orbit_frame_q_NO(double orbit_rate_rad_s, double t_s);

class Spacecraft {
 public:
  Spacecraft(const ClosedLoopSpec& spec, double orbit_period_s);

  //! [N·m] external torque in B at time t for the attitude q_NB.
  Eigen::Vector3d disturbance_B_Nm(const Quaternion& q_NB, double t_s) const {
    return disturbance_B_Nm(q_NB, at_time(t_s));
  }
  //! Integrates `state` from t to t + dt with the wheel motor torques `tau_wheels_Nm` held.
  void step(BodyState& state, const Eigen::VectorXd& tau_wheels_Nm, double t_s, double dt_s) const {
    advance(state, tau_wheels_Nm, t_s, dt_s, 1);
  }
  //! `steps` steps of dt from t0 (the i-th from t0 + i·dt) with the torques held: step() at each, one call.
  void advance(BodyState& state, const Eigen::VectorXd& tau_wheels_Nm, double t0_s, double dt_s,
               long long steps) const;

  const Eigen::Matrix3d& inertia() const { return inertia_; }
  const Eigen::MatrixXd& wheel_axes() const { return axes_B_; }
  double orbit_rate_rad_s() const { return orbit_rate_rad_s_; }

 private:
  //! What the external torque at a time needs of the time alone.
  struct TimeTerms {
    Eigen::Vector3d tau_B_Nm = Eigen::Vector3d::Zero();  //!< [N·m] in B: constant + periodic
    Eigen::Vector3d zenith_N = Eigen::Vector3d::Zero();  //!< [-] the zenith in N (gravity gradient)
  };
  TimeTerms at_time(double t_s) const;
  Eigen::Vector3d disturbance_B_Nm(const Quaternion& q_NB, const TimeTerms& at) const;
  //! advance() with `kWheels` wheels known at compile time (the 3 or 4 a spec validates; 0: at run time).
  template <int kWheels>
  void integrate(BodyState& state, const Eigen::VectorXd& tau_wheels_Nm, double t0_s, double dt_s,
                 long long steps) const;

  Eigen::Matrix3d inertia_;
  Eigen::Matrix3d inertia_inv_;
  Eigen::MatrixXd axes_B_;
  DisturbanceSpec disturbance_;
  double orbit_rate_rad_s_;
};

}  // namespace tetra::sim
