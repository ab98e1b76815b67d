#pragma once
// The attitude controller of the closed-loop simulator: PD (or PID) with rate feedback on the
// *estimated* attitude and rate (the fusion pipeline's output), gains from a stated bandwidth and
// damping (closed_loop_spec.hpp), torque distributed on the wheels with their limits.
//
//   θ   = 2·vec(q_RB̂)·sign(w)        attitude error of the estimate from the reference (small angles: rad)
//   δω  = ω̂_BN_B − C_BR·ω_RN_R      rate error
//   u   = −I·(ω_n²·θ + 2ζω_n·δω + (ω_n²/T_i)·∫θ dt) + I·C_BR·α_RN_R + ω̂ × (I·ω̂ + G·h_w)
//   τ_w = −G⁺·u, scaled down together when one exceeds the torque limit, then each clipped so that
//         its momentum stays within the limit over the control period.
// The reference is evaluated at the estimate's own time, so a late estimate is compared with where
// the spacecraft should have been then.
//
// Stale, missing or lost attitude, as flight software would handle it: an estimate older than
// hold_after_s → the last command is held; older than safe_after_s (or none yet), or one whose
// estimator says the attitude is lost (LOST: too few gyros left to determine it) → safe mode, wheel
// torques zero (the body keeps its momentum: no torque is computed from an attitude or a rate nobody
// knows). A fresh estimate that knows the attitude resumes normal control. Epochs in each state are
// counted.
//
// Anti-windup: the integral of θ is frozen while the command is limited (scaled to the torque limit or
// clipped at a wheel's momentum limit: conditional integration), not advanced in hold and cleared in
// safe mode, so a saturated or interrupted period does not leave a charged integrator behind.
// Momentum management (desaturation) is not modelled: a wheel at its momentum limit stops taking
// torque in that direction (momentum_limited), the uncontrolled axis drifts under the disturbances,
// and the run reports it (max_momentum_fraction, momentum_limited_s, recovered: false).

#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/sim/closed_loop_spec.hpp"
#include "tetra/sim/guidance.hpp"

namespace tetra::sim {

//! What the controller knows of the attitude: an estimate and its time.
struct AttitudeKnowledge {
  double time_s = 0.0;                                         //!< [s] time the estimate refers to
  Quaternion q_NB = Quaternion::Identity();                    //!< estimated B → N
  Eigen::Vector3d omega_BN_B_rad_s = Eigen::Vector3d::Zero();  //!< [rad/s] estimated inertial rate
  bool attitude_known = true;  //!< false: the estimator has lost the attitude (its mode LOST)
};

enum class ControlState : std::uint8_t { kNormal, kHold, kSafe };
const char* to_string(ControlState state);  // "normal", "hold", "safe"

struct ControlOutput {
  Eigen::VectorXd tau_wheels_Nm;  //!< [N·m] motor torque per wheel (on the wheel)
  ControlState state = ControlState::kNormal;
  bool torque_limited = false;    //!< the commanded torque was scaled down
  bool momentum_limited = false;  //!< a wheel torque was clipped at its momentum limit
};

struct ControlCounters {
  std::uint64_t normal_epochs = 0;
  std::uint64_t hold_epochs = 0;
  std::uint64_t safe_epochs = 0;
  std::uint64_t safe_entries = 0;  //!< transitions into safe mode
  std::uint64_t lost_epochs = 0;   //!< safe epochs because the estimate said the attitude was lost
};

class AttitudeController {
 public:
  AttitudeController(const ClosedLoopSpec& spec, const Eigen::MatrixXd& wheel_axes_B,
                     double orbit_rate_rad_s);

  //! Wheel torques for the control period starting at `t_s` from the latest knowledge (none: no
  //! estimate received yet), the wheel momenta h_w (tachometers) and the period `dt_s`.
  ControlOutput command(double t_s, const std::optional<AttitudeKnowledge>& latest,
                        const Eigen::VectorXd& h_wheels_Nms, double dt_s);

  const ControlCounters& counters() const { return counters_; }
  const Guidance& guidance() const { return guidance_; }
  //! [N·m] body torque of the last normal command (before the wheel limits).
  const Eigen::Vector3d& last_torque_B_Nm() const { return last_torque_B_Nm_; }
  //! [rad·s] the integral of the attitude error (zero for PD).
  const Eigen::Vector3d& integral_rad_s() const { return integral_rad_s_; }

 private:
  Eigen::Vector3d body_torque(const AttitudeKnowledge& k, const Eigen::VectorXd& h_wheels_Nms, double dt_s);
  ControlOutput distribute(const Eigen::Vector3d& u_B_Nm, const Eigen::VectorXd& h_wheels_Nms,
                           double dt_s) const;

  ClosedLoopSpec spec_;
  Eigen::MatrixXd axes_B_;
  Eigen::MatrixXd axes_pinv_;
  Guidance guidance_;
  double kp_per_s2_;  //!< ω_n²
  double kd_per_s_;   //!< 2ζω_n
  double ki_per_s3_;  //!< ω_n²/T_i (0 = PD)
  Eigen::Vector3d integral_rad_s_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_torque_B_Nm_ = Eigen::Vector3d::Zero();
  bool last_limited_ = false;  //!< the previous command was torque- or momentum-limited
  ControlState state_ = ControlState::kSafe;
  ControlCounters counters_;
};

}  // namespace tetra::sim
