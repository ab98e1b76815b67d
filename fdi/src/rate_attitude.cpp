#include "rate_attitude.hpp"

#include <algorithm>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

Eigen::Vector3d fault_rate_bound(const Subset& s, const Eigen::VectorXd& parity_ema, double sqrt_period) {
  Eigen::Vector3d bound = Eigen::Vector3d::Zero();
  if (s.dof < 1) return bound;
  for (Eigen::Index i = 0; i < s.pinv.cols(); ++i) {
    if (!has_gyro(s.mask, static_cast<int>(i) + 1)) continue;
    double wp = 0.0;
    double ww = 0.0;
    for (int r = 0; r < s.dof; ++r) {
      const double w = s.parity(r, i) * sqrt_period;
      wp += w * parity_ema[r];
      ww += w * w;
    }
    const double f = wp / ww;
    bound = bound.cwiseMax((s.pinv.col(i) * f).cwiseAbs());
  }
  return bound;
}

Eigen::Vector3d fault_angle_error(const Subset& s, int id, const Eigen::VectorXd& parity_ema,
                                  double sqrt_period, double span_s) {
  if (!s.observable || s.dof < 1) return Eigen::Vector3d::Zero();
  const Eigen::VectorXd w = s.parity.col(id - 1) * sqrt_period;
  // parity_ema is sized for N − 3 parity rows; this subset has s.dof of them (fewer once a gyro is out).
  const double f = w.dot(parity_ema.head(s.dof)) / std::max(w.squaredNorm(), 1e-300);
  return s.pinv.col(id - 1) * f * span_s;
}

RateAttitude::RateAttitude(const PipelineConfig& config)
    : config_(config),
      propagator_(config.initial_q_RB, config.latitude_deg
                                           ? std::optional<double>(*config.latitude_deg * kDegToRad)
                                           : std::nullopt) {}

void RateAttitude::reset(const Quaternion& q0_RB) {
  propagator_.reset(q0_RB);
  omega_meas_.setZero();
  omega_prev_.setZero();
  lost_since_ns_ = -1;
}

void RateAttitude::measure(const Subset& s, const EpochFrame& frame) {
  if (s.observable) omega_meas_ = apply_pinv(s.pinv, frame.usable, frame.y_rad_s.data());
}

bool RateAttitude::measure_unprepared(const GyroGeometry& geometry, const EpochFrame& frame) {
  if (!geometry.observable(frame.usable)) return false;
  omega_meas_ = apply_pinv(*geometry.pseudoinverse(frame.usable), frame.usable, frame.y_rad_s.data());
  return true;
}

void RateAttitude::propagate(const EpochFrame& frame, const Subset& sol, const Subset* fallback,
                             const Eigen::Vector3d& fault_bound_rad_s) {
  Eigen::Vector3d bound = fault_bound_rad_s;
  if (!sol.observable) {
    // Rate unobservable: keep the last estimate and bound what the motion may have changed since.
    if (lost_since_ns_ < 0) lost_since_ns_ = frame.now_ns;
    const double t_lost = ns_to_seconds(frame.now_ns - lost_since_ns_) + frame.dt_s;
    bound += Eigen::Vector3d::Constant(config_.max_angular_acceleration_dps2 * kDegToRad * t_lost);
  } else {
    lost_since_ns_ = -1;
  }
  const Subset& noise = sol.observable ? sol : *fallback;
  (void)propagator_.step(0.5 * (omega_prev_ + omega_meas_), frame.dt_s, noise.arw_sq_rad2_s,
                         noise.bias_sigma_rad_s, bound);  // trapezoid
}

}  // namespace tetra::fdi::detail
