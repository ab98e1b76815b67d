#include "tetra/sim/controller.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "tetra/core/units.hpp"

namespace tetra::sim {

const char* to_string(ControlState state) {
  switch (state) {
    case ControlState::kNormal:
      return "normal";
    case ControlState::kHold:
      return "hold";
    case ControlState::kSafe:
      return "safe";
  }
  return "?";
}

AttitudeController::AttitudeController(const ClosedLoopSpec& spec, const Eigen::MatrixXd& wheel_axes_B,
                                       double orbit_rate_rad_s)
    : spec_(spec),
      axes_B_(wheel_axes_B),
      axes_pinv_(wheel_axes_B.completeOrthogonalDecomposition().pseudoInverse()),
      guidance_(spec.pointing, orbit_rate_rad_s) {
  const double wn = 2.0 * kPi * spec.controller.bandwidth_hz;
  kp_per_s2_ = wn * wn;
  kd_per_s_ = 2.0 * spec.controller.damping * wn;
  ki_per_s3_ = spec.controller.integral_time_s > 0.0 ? kp_per_s2_ / spec.controller.integral_time_s : 0.0;
}

Eigen::Vector3d AttitudeController::body_torque(const AttitudeKnowledge& k,
                                                const Eigen::VectorXd& h_wheels_Nms, double dt_s) {
  const PointingReference ref = guidance_.at(k.time_s);
  const Quaternion q_RB = canonical(ref.q_NR.conjugate() * k.q_NB);
  const Eigen::Vector3d theta = 2.0 * q_RB.vec();
  const Eigen::Vector3d omega_ref_B = q_RB.conjugate() * ref.omega_RN_R_rad_s;
  const Eigen::Vector3d alpha_ref_B = q_RB.conjugate() * ref.alpha_RN_R_rad_s2;
  const Eigen::Vector3d d_omega = k.omega_BN_B_rad_s - omega_ref_B;
  if (ki_per_s3_ > 0.0 && !last_limited_) integral_rad_s_ += theta * dt_s;  // frozen while limited
  const Eigen::Matrix3d& inertia = spec_.inertia_kg_m2;
  const Eigen::Vector3d& w = k.omega_BN_B_rad_s;
  const Eigen::Vector3d feedback =
      -(inertia * (kp_per_s2_ * theta + kd_per_s_ * d_omega + ki_per_s3_ * integral_rad_s_));
  return feedback + inertia * alpha_ref_B + w.cross(inertia * w + axes_B_ * h_wheels_Nms);
}

ControlOutput AttitudeController::distribute(const Eigen::Vector3d& u_B_Nm,
                                             const Eigen::VectorXd& h_wheels_Nms, double dt_s) const {
  ControlOutput out;
  out.tau_wheels_Nm = -(axes_pinv_ * u_B_Nm);
  const double tau_max = spec_.wheels.max_torque_Nm;
  const double largest = out.tau_wheels_Nm.cwiseAbs().maxCoeff();
  if (largest > tau_max) {
    out.tau_wheels_Nm *= tau_max / largest;
    out.torque_limited = true;
  }
  const double h_max = spec_.wheels.max_momentum_Nms;
  for (Eigen::Index i = 0; i < out.tau_wheels_Nm.size(); ++i) {
    const double high = (h_max - h_wheels_Nms[i]) / dt_s;
    const double low = (-h_max - h_wheels_Nms[i]) / dt_s;
    const double clipped = std::clamp(out.tau_wheels_Nm[i], std::min(low, 0.0), std::max(high, 0.0));
    if (clipped != out.tau_wheels_Nm[i]) out.momentum_limited = true;
    out.tau_wheels_Nm[i] = clipped;
  }
  return out;
}

ControlOutput AttitudeController::command(double t_s, const std::optional<AttitudeKnowledge>& latest,
                                          const Eigen::VectorXd& h_wheels_Nms, double dt_s) {
  const double age_s = latest ? t_s - latest->time_s : INFINITY;
  const bool lost = latest && !latest->attitude_known;
  const ControlState previous = state_;
  if (lost) {
    state_ = ControlState::kSafe;  // whatever its age: an attitude nobody knows is never steered on
  } else if (age_s <= spec_.controller.hold_after_s) {
    state_ = ControlState::kNormal;
  } else if (age_s <= spec_.controller.safe_after_s && previous != ControlState::kSafe) {
    state_ = ControlState::kHold;
  } else {
    state_ = ControlState::kSafe;
  }
  ControlOutput out;
  switch (state_) {
    case ControlState::kNormal:
      last_torque_B_Nm_ = body_torque(*latest, h_wheels_Nms, dt_s);
      out = distribute(last_torque_B_Nm_, h_wheels_Nms, dt_s);
      ++counters_.normal_epochs;
      break;
    case ControlState::kHold:
      out = distribute(last_torque_B_Nm_, h_wheels_Nms, dt_s);  // the integral is not advanced
      ++counters_.hold_epochs;
      break;
    case ControlState::kSafe:
      out.tau_wheels_Nm = Eigen::VectorXd::Zero(axes_B_.cols());
      integral_rad_s_.setZero();
      if (previous != ControlState::kSafe) ++counters_.safe_entries;
      ++counters_.safe_epochs;
      if (lost) ++counters_.lost_epochs;
      break;
  }
  last_limited_ = out.torque_limited || out.momentum_limited;
  out.state = state_;
  return out;
}

}  // namespace tetra::sim
