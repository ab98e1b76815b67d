#include "rate_attitude.hpp"

#include <algorithm>
#include <cmath>

#include "quadrature.hpp"
#include "tetra/core/allan_stats.hpp"
#include "tetra/core/correlated_noise.hpp"  // kGaussMarkovSigmaPerB
#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi::detail {

namespace {

//! [rad/s] f_i = wᵢᵀp̄/|wᵢ|²: the fault on gyro i (column i of the subset's parity) that explains p̄.
double single_gyro_fault(const Subset& s, Eigen::Index i, const Eigen::VectorXd& parity_ema,
                         double sqrt_period) {
  double wp = 0.0;
  double ww = 0.0;
  for (int r = 0; r < s.dof; ++r) {
    const double w = s.parity(r, i) * sqrt_period;
    wp += w * parity_ema[r];
    ww += w * w;
  }
  return wp / ww;
}
}  // namespace

Eigen::Vector3d unchecked_rate_bound(const Subset& full, const Subset& used, const Eigen::VectorXd& p,
                                     double sqrt_period) {
  Eigen::Vector3d bound = Eigen::Vector3d::Zero();
  if (full.dof < 1) return bound;
  for (Eigen::Index i = 0; i < used.pinv.cols(); ++i) {
    if (!has_gyro(used.mask, static_cast<int>(i) + 1)) continue;
    const double f = single_gyro_fault(full, i, p, sqrt_period);
    bound = bound.cwiseMax((used.pinv.col(i) * f).cwiseAbs());
  }
  return bound;
}

Eigen::Vector3d fault_rate_bound(const Subset& s, const Eigen::VectorXd& parity_ema, double sqrt_period) {
  return unchecked_rate_bound(s, s, parity_ema, sqrt_period);
}

double fault_size_bound(const Subset& s, const Eigen::VectorXd& parity_ema, double sqrt_period) {
  double f = 0.0;
  if (s.dof < 1) return f;
  for (Eigen::Index i = 0; i < s.pinv.cols(); ++i) {
    if (has_gyro(s.mask, static_cast<int>(i) + 1))
      f = std::max(f, std::abs(single_gyro_fault(s, i, parity_ema, sqrt_period)));
  }
  return f;
}

Eigen::Vector3d fault_angle_error(const Subset& s, int id, const Eigen::VectorXd& parity_ema,
                                  double sqrt_period, double span_s) {
  if (!s.observable || s.dof < 1) return Eigen::Vector3d::Zero();
  const Eigen::VectorXd w = s.parity.col(id - 1) * sqrt_period;
  // parity_ema is sized for N − 3 parity rows; this subset has s.dof of them (fewer once a gyro is out).
  const double f = w.dot(parity_ema.head(s.dof)) / std::max(w.squaredNorm(), 1e-300);
  return s.pinv.col(id - 1) * f * span_s;
}

std::vector<GyroNoiseModel> noise_models(const Calibration& cal, const GyroSeries& series,
                                         const PipelineConfig& config) {
  // σ_GM = kGaussMarkovSigmaPerB·B: the Gauss–Markov process whose Allan peak is IEEE 952's 0.664·B floor.
  std::vector<GyroNoiseModel> out(cal.gyros.size());
  for (std::size_t i = 0; i < cal.gyros.size(); ++i) {
    const GyroConstants& c = series.constants(static_cast<int>(i) + 1);
    GyroNoiseModel& m = out[i];
    m.arw_rad_rts = c.arw_rad_rts;
    m.bias_sigma_rad_s = c.bias_sigma_rad_s;
    m.gm_sigma_rad_s = kGaussMarkovSigmaPerB * c.bias_instability_rad_s;
    m.gm_correlation_s = config.bias_instability_correlation_s;
    const auto& noise = cal.gyros[i].noise;
    if (noise && noise->rate_random_walk_dps_per_rts)
      m.rrw_rad_s_rts = *noise->rate_random_walk_dps_per_rts * kDegToRad;
    if (noise && noise->rate_ramp_dps_per_s)
      m.ramp_rad_s2 = std::abs(*noise->rate_ramp_dps_per_s) * kDegToRad;
  }
  return out;
}

RateAttitude::RateAttitude(const PipelineConfig& config, std::vector<GyroNoiseModel> gyros)
    : config_(config),
      propagator_(config.initial_q_RB, config.latitude_deg
                                           ? std::optional<double>(*config.latitude_deg * kDegToRad)
                                           : std::nullopt),
      mekf_(std::move(gyros)),
      snapshots_(mekf_),
      gate_chi2_(allan::chi2_quantile(1.0 - allocated_probability(config, BudgetTest::kReferenceGate), 3.0)),
      sigma_ref_rad_(config.reference_sigma_arcsec * kArcsecToRad) {}

void RateAttitude::reset(const Quaternion& q0_RB) {
  sigma_ref_rad_ = config_.reference_sigma_arcsec * kArcsecToRad;
  propagator_.reset(q0_RB);
  mekf_.reset(config_.initial_sigma_deg * kDegToRad);
  snapshots_.reset();
  omega_meas_.setZero();
  omega_prev_.setZero();
  correction_.setZero();
  lost_since_ns_ = -1;
  measured_ns_ = -1;
  slope_prev_.setZero();
  accel_seen_.setZero();
  have_slope_ = false;
  set_changed_ = false;
  reference_seen_ = false;
  rejected_run_ = 0;
  last_chi2_ = 0.0;
}

Eigen::Vector3d RateAttitude::sigma_rad() const {
  const Eigen::Vector3d f = mekf_.attitude_sigma_rad();
  const Eigen::Vector3d b = propagator_.sigma_rad();  // the bound alone: its noise inputs are zero
  return root_sum_square(f, b);
}

void RateAttitude::parity(const Subset& s, const Eigen::VectorXd& p, double sqrt_period) {
  if (!reference_seen_ || s.dof < 1) return;
  const Eigen::Vector3d dtheta = mekf_.update_parity(s.parity, s.dof, s.mask, sqrt_period, p.data());
  propagator_.rotate(quat_exp(dtheta));  // the bound (a fault's, a lost rate's) kept
}

Eigen::Vector3d RateAttitude::curvature_rad_s(double dt_s, double period_s) const {
  if (!have_slope_ || set_changed_ || dt_s <= 0.0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d slope = (omega_meas_ - omega_prev_) / dt_s;
  return -(period_s * period_s / 12.0) * (slope - slope_prev_) / dt_s;
}

bool RateAttitude::predict_reference(const Quaternion& q_ref_RB, double dt_s, double period_s,
                                     Eigen::Vector3d& z, Eigen::Matrix3d& S) const {
  if (!reference_seen_) return false;
  // The step propagate() will take: the trapezoid rate with its curvature correction, less the bias
  // correction (the Earth rate's share is below a milliarcsecond over a step).
  const Eigen::Vector3d omega =
      0.5 * (omega_prev_ + omega_meas_) + curvature_rad_s(dt_s, period_s) - correction_;
  const Quaternion q_pred = propagator_.q_RB() * quat_exp(omega * dt_s);
  z = quat_log(q_pred.conjugate() * q_ref_RB);
  const double sigma_ref = sigma_ref_rad_;
  const Eigen::Vector3d bound = propagator_.sigma_rad();
  S = mekf_.covariance().topLeftCorner<3, 3>();
  S.diagonal() += bound.cwiseProduct(bound) + Eigen::Vector3d::Constant(sigma_ref * sigma_ref);
  return true;
}

ReferenceUse RateAttitude::reference(const Quaternion& q_ref_RB, bool may_reinitialize) {
  const double sigma_ref = sigma_ref_rad_;
  if (!reference_seen_) {
    // The first sample sets the attitude (replay and service alike): known to the reference's σ from now on.
    reference_seen_ = true;
    propagator_.reset(q_ref_RB);
    mekf_.reset_attitude(sigma_ref);
    return ReferenceUse::kInitialized;
  }
  // A bound (unresolved fault, lost rate) becomes a 1σ of the filter: the reference can then correct it.
  const Eigen::Vector3d bound = propagator_.sigma_rad();
  mekf_.add_attitude_variance(bound.cwiseProduct(bound));
  propagator_.reset(propagator_.q_RB());
  const ReferenceUpdate u = mekf_.update_reference(propagator_.q_RB(), q_ref_RB, sigma_ref, gate_chi2_);
  last_chi2_ = u.chi2;
  if (u.accepted) {
    rejected_run_ = 0;
    last_correction_rad_ = u.correction_rad;
    propagator_.reset(propagator_.q_RB() * quat_exp(u.correction_rad));
    return ReferenceUse::kAccepted;
  }
  if (++rejected_run_ < design::reference_gate_reset_count || !may_reinitialize)
    return ReferenceUse::kRejected;
  // Every recent sample disagrees: the estimate, not the reference, is wrong (e.g. after a lost rate).
  rejected_run_ = 0;
  propagator_.reset(q_ref_RB);
  mekf_.reset_attitude(sigma_ref);
  return ReferenceUse::kReinitialized;
}

void RateAttitude::measure(const Subset& s, const EpochFrame& frame) {
  if (!s.observable) return;
  omega_meas_ = apply_pinv(s.pinv, frame.usable, frame.y_rad_s.data());
  if (lost_since_ns_ >= 0 && measured_ns_ >= 0 && frame.now_ns != measured_ns_) {
    // The first rate after a lost one: the previous epoch's, held since the last one measured, is no sample
    // of the motion (a slew moved on by a·τ meanwhile). The step takes it on the line between the last
    // measured rate and this one, and no curvature (its slopes straddle the held stretch).
    const double span_s = ns_to_seconds(frame.now_ns - measured_ns_);
    const double held_s = span_s - frame.dt_s;
    if (span_s > 0.0 && held_s > 0.0) omega_prev_ += (omega_meas_ - omega_prev_) * (held_s / span_s);
    have_slope_ = false;
  }
  measured_ns_ = frame.now_ns;
}

bool RateAttitude::measure_unprepared(const GyroGeometry& geometry, const EpochFrame& frame) {
  if (!geometry.observable(frame.usable)) return false;
  omega_meas_ = apply_pinv(*geometry.pseudoinverse(frame.usable), frame.usable, frame.y_rad_s.data());
  return true;
}

double RateAttitude::gap_bound_rad(double tau_s, const Subset& s) const {
  // A slew faster than the configured bound shows in the slopes before the gap: a body that turned at that
  // acceleration may go on doing so unseen. A slope is the difference of two noisy rates over a step, its
  // 1σ √(2N²/T)/T per axis (T the step they were seen over); beyond design::slope_noise_sigmas of it, the
  // seen slope is the body's. The angle it may hide is about any axis, and the body turns on after the gap,
  // carrying an error about one axis into the others: the bound is the same on every axis, the acceleration's
  // norm.
  double a = config_.max_angular_acceleration_dps2 * kDegToRad;
  const double step_s = accel_decay_dt_s_;
  if (s.observable && step_s > 0.0) {
    const Eigen::Vector3d noise = (2.0 * s.arw_sq_rad2_s / step_s).cwiseSqrt() / step_s;
    a = std::max(a, (accel_seen_ - design::slope_noise_sigmas * noise).cwiseMax(0.0).norm());
  }
  return 0.25 * tau_s * tau_s * a;
}

void RateAttitude::propagate(const EpochFrame& frame, const Subset& sol, const Subset* fallback,
                             const Eigen::Vector3d& fault_bound_rad_s, double period_s) {
  Eigen::Vector3d bound = fault_bound_rad_s;
  if (!sol.observable) {
    // Rate unobservable: keep the last estimate and bound what the motion may have changed since, at the
    // configured acceleration bound or at the acceleration the gyros saw just before, whichever is larger (a
    // slew beyond the bound must not make the held rate's error look small).
    if (lost_since_ns_ < 0) lost_since_ns_ = frame.now_ns;
    const double t_lost = ns_to_seconds(frame.now_ns - lost_since_ns_) + frame.dt_s;
    bound += accel_seen_.cwiseMax(config_.max_angular_acceleration_dps2 * kDegToRad) * t_lost;
  } else {
    lost_since_ns_ = -1;
    if (frame.dt_s != accel_decay_dt_s_) {  // the step is nearly always the last one's: one exp per change
      accel_decay_dt_s_ = frame.dt_s;
      accel_decay_ = std::exp(-frame.dt_s / design::accel_memory_s);
    }
    accel_seen_ =
        (accel_seen_ * accel_decay_).cwiseMax(((omega_meas_ - omega_prev_) / frame.dt_s).cwiseAbs());
  }
  const Subset& noise = sol.observable ? sol : *fallback;
  // The rate as the filter sees it: the trapezoid of the estimates with its curvature correction, less the
  // bias estimates' projection (zero without a reference: then the attitude is the gyros' alone).
  if (sol.observable) correction_ = mekf_.rate_correction(sol.pinv, sol.mask);
  const Eigen::Vector3d omega =
      0.5 * (omega_prev_ + omega_meas_) + curvature_rad_s(frame.dt_s, period_s) - correction_;
  slope_prev_ = (omega_meas_ - omega_prev_) / frame.dt_s;
  have_slope_ = !set_changed_;  // a slope across two gyro sets is not the body's
  set_changed_ = false;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  (void)propagator_.step(omega, frame.dt_s, zero, zero, bound);
  mekf_.propagate(propagator_.last_increment(), noise.pinv, noise.mask, omega, frame.dt_s);
}

}  // namespace tetra::fdi::detail
