#include "parity_detector.hpp"

#include <algorithm>
#include <cmath>

namespace tetra::fdi::detail {

Cusum::Cusum(Eigen::Index dmax)
    : s_(Eigen::VectorXd::Zero(dmax)), sum_(Eigen::VectorXd::Zero(dmax)), dp_(Eigen::VectorXd::Zero(dmax)) {}

void Cusum::clear(std::int64_t next_index) {
  pos_ = neg_ = 0.0;
  pos_start_ = neg_start_ = next_index;
  s_.setZero();
  sum_.setZero();
  n_ = 0;
  start_ = next_index;
}

void Cusum::zero() {
  pos_ = neg_ = 0.0;
  s_.setZero();
}

double Cusum::step(const Eigen::VectorXd& p, int d, double k, std::int64_t index, std::int64_t& onset) {
  if (d == 1) {
    if (pos_ <= 0.0) pos_start_ = index;
    if (neg_ <= 0.0) neg_start_ = index;
    pos_ = std::max(0.0, pos_ + p[0] - k);
    neg_ = std::max(0.0, neg_ - p[0] - k);
    onset = pos_ >= neg_ ? pos_start_ : neg_start_;
    return std::max(pos_, neg_);
  }
  // Crosier's multivariate CUSUM: C = |S + p|; S ← 0 if C ≤ k, else (S + p)(1 − k/C).
  const auto n = static_cast<Eigen::Index>(d);
  if (s_.head(n).squaredNorm() == 0.0) {
    start_ = index;
    sum_.setZero();
    n_ = 0;
  }
  dp_.head(n) = s_.head(n) + p.head(n);
  const double c = dp_.head(n).norm();
  if (c <= k) {
    s_.setZero();
  } else {
    s_.head(n) = dp_.head(n) * (1.0 - k / c);
  }
  sum_.head(n) += p.head(n);
  ++n_;
  onset = start_;
  return s_.head(n).norm();
}

ParityDetector::ParityDetector(int n_gyros, double nominal_window_s)
    : cusum_(std::max(1, n_gyros - 3)),
      level_cusum_(std::max(1, n_gyros - 3)),
      nominal_window_s_(nominal_window_s) {
  const Eigen::Index dmax = std::max(1, n_gyros - 3);
  level_ = Eigen::VectorXd::Zero(dmax);
  p_slow_ = Eigen::VectorXd::Zero(dmax);
  p_ema_ = Eigen::VectorXd::Zero(dmax);
  p_ = Eigen::VectorXd::Zero(dmax);
  p_raw_ = Eigen::VectorXd::Zero(dmax);
  dp_ = Eigen::VectorXd::Zero(dmax);
  wander_mean_ = Eigen::VectorXd::Zero(dmax);
  wander_in_ = Eigen::VectorXd::Zero(dmax);
}

void ParityDetector::restart(std::int64_t next_index) {
  cusum_mask_ = 0;
  cusum_.clear(next_index);
  level_cusum_.clear(next_index);
  level_alarm_ = false;
  episode_ = false;
  p_ema_.setZero();
  p_slow_.setZero();
  slow_age_s_ = 0.0;
  restart_wander();
}

void ParityDetector::open_episode() {
  episode_ = true;
  level_held_ = false;
  level_n_ = 0;
  level_.setZero();
}

void ParityDetector::close_episode(std::int64_t next_index) {
  episode_ = false;
  level_held_ = false;
  level_n_ = 0;
  level_alarm_ = false;
  level_cusum_.clear(next_index);
}

bool ParityDetector::parity_nominal(const Subset& s) const {
  if (s.dof < 1 || slow_age_s_ < nominal_window_s_) return false;
  const auto d = static_cast<Eigen::Index>(s.dof);
  const double var = slow_var_ + s.bias_wander_sigma * s.bias_wander_sigma;
  return p_slow_.head(d).squaredNorm() < s.nominal_threshold * var;
}

void ParityDetector::restart_after_alarm() {
  if (level_alarm_) {
    level_cusum_.zero();
  } else {
    cusum_.zero();
  }
}

void ParityDetector::slow_terms(double dt_s, double qs) {
  if (dt_s == slow_dt_s_ && qs == slow_qs_) return;  // the step and the subset nearly always the last ones
  slow_dt_s_ = dt_s;
  slow_qs_ = qs;
  // The slow mean: white unit-variance input gives an EMA of variance β/(2 − β) in steady state.
  const double beta = std::min(1.0, dt_s / nominal_window_s_);
  slow_beta_ = beta;
  // Quantization: each sample's error term is a difference u_k − u_{k−1} (1σ of u: quantization_sigma), whose
  // EMA telescopes: β·Σ_j (1 − β)^j (u_{k−j} − u_{k−j−1}) = β·u_k − β²·Σ_j (1 − β)^j u_{k−j−1}, of variance
  // β²(1 + β/(2 − β))·σ_u² = 2β²/(2 − β)·σ_u².
  slow_var_ = beta / (2.0 - beta) + 2.0 * beta * beta / (2.0 - beta) * qs * qs;
}

Detection ParityDetector::update(const EpochFrame& frame, const Subset& s, GyroMask active,
                                 double sqrt_period, double calibration_bound, Health& health) {
  Detection d;
  d.onset_index = frame.index;
  // The χ² sees one sample: with quantization its own whitening (white noise and quantization error). Both
  // leave out the calibration's term, bounded by `calibration_bound` in either whitening (the sample's
  // columns are no longer than the white noise's). The CUSUM sums: it takes the parity as it is and the bound
  // in its reference (below), since moving each sample towards 0 barely moves the mean of noisy samples.
  double sum_sq = apply_parity(s, frame.usable, frame.y_rad_s.data(), sqrt_period, p_.data());
  const auto dof = static_cast<Eigen::Index>(s.dof);
  p_raw_.head(dof) = p_.head(dof);
  // A tracked wander is taken off the full subset's parity (its mean before this epoch), and with it its
  // share of the bound.
  double relief = 0.0;
  if (s.wander_step_var > 0.0 && frame.usable == active && cusum_mask_ == active && !wander_fresh_) {
    p_.head(dof) -= wander_mean_.head(dof);
    sum_sq = p_.head(dof).squaredNorm();
    relief = s.wander_relief;
  }
  double chi2 = shrink_by(p_.data(), s.dof, calibration_bound - relief, sum_sq);
  if (s.quantized)
    chi2 = shrink_by(
        dp_.data(), s.dof, calibration_bound,
        apply_whitened(s.sample_parity, s.dof, frame.usable, frame.y_rad_s.data(), sqrt_period, dp_.data()));
  health.chi2 = chi2;
  health.chi2_threshold = s.chi2_threshold;
  health.parity_residual = s.dof >= 1 ? std::sqrt(chi2) : 0.0;
  if (s.dof >= 1 && chi2 > s.chi2_threshold)
    d = {true, DetectionTest::kChi2, chi2, frame.index, false, s.chi2_threshold, s.dof};
  if (frame.usable != active || s.dof < 1) return d;

  d.cusum_ran = true;
  if (cusum_mask_ != active) {  // a new gyro set: its CUSUM starts from zero, any episode level with it
    cusum_mask_ = active;
    cusum_.clear(frame.index);
    level_cusum_.clear(frame.index);
    episode_ = false;
    p_ema_.setZero();
    p_slow_.setZero();
    slow_age_s_ = 0.0;
    restart_wander();
  }
  const double alpha = std::min(1.0, frame.dt_s / 2.0);  // EMA time constant 2 s
  for (int r = 0; r < s.dof; ++r) p_ema_[r] += alpha * (p_[r] - p_ema_[r]);
  slow_terms(frame.dt_s, s.quantization_sigma);
  for (int r = 0; r < s.dof; ++r) p_slow_[r] += slow_beta_ * (p_[r] - p_slow_[r]);
  slow_age_s_ += frame.dt_s;
  std::int64_t onset = d.onset_index;
  // A calibration term m with |m| ≤ D moves the CUSUM's sum by at most D per epoch: with the reference k + D
  // the statistic never exceeds that of the noise alone (d = 1; for d ≥ 2 its radial drift). A tracked wander
  // needs no share of D (its innovation is white): only the tracker's lag behind a stated ramp.
  const double stat =
      cusum_.step(cusum_input(s), s.dof, s.cusum_k + calibration_bound - s.wander_relief, frame.index, onset);
  health.cusum = stat;
  health.cusum_threshold = s.cusum_h;
  if (level_change(s, frame.index, d)) {
    level_alarm_ = true;
    return d;
  }
  if (stat > s.cusum_h && !d.alarm) {
    d.alarm = true;
    d.test = DetectionTest::kCusum;
    d.statistic = stat;
    d.onset_index = onset;
    d.threshold = s.cusum_h;
  }
  level_alarm_ = false;
  return d;
}

const Eigen::VectorXd& ParityDetector::cusum_input(const Subset& s) {
  const double q = s.wander_step_var;
  if (!(q > 0.0)) return p_raw_;
  const auto dof = static_cast<Eigen::Index>(s.dof);
  if (wander_fresh_) {
    wander_mean_.setZero();
    wander_var_ = s.bias_wander_sigma * s.bias_wander_sigma;
    wander_fresh_ = false;
  }
  const double p_pred = wander_var_ + q;
  wander_in_.head(dof) = (p_raw_.head(dof) - wander_mean_.head(dof)) / std::sqrt(1.0 + p_pred);
  if (episode_) {  // held: the fault is not the wander
    wander_var_ = p_pred;
    return wander_in_;
  }
  const double gain = p_pred / (1.0 + p_pred);
  wander_mean_.head(dof) += gain * (p_raw_.head(dof) - wander_mean_.head(dof));
  wander_var_ = (1.0 - gain) * p_pred;
  return wander_in_;
}

bool ParityDetector::level_change(const Subset& s, std::int64_t index, Detection& d) {
  if (!episode_) return false;
  const auto dof = static_cast<Eigen::Index>(s.dof);
  if (!level_held_) {
    level_.head(dof) += p_.head(dof);
    if (++level_n_ < s.level_epochs) return false;
    level_.head(dof) /= static_cast<double>(level_n_);
    level_held_ = true;
    level_cusum_.clear(index + 1);
    return false;
  }
  dp_.head(dof) = p_.head(dof) - level_.head(dof);
  std::int64_t onset = index;
  const double stat = level_cusum_.step(dp_, s.dof, s.level_k, index, onset);
  if (stat <= s.level_h) return false;
  d = {true, DetectionTest::kLevel, stat, onset, true, s.level_h, 0};
  return true;
}

}  // namespace tetra::fdi::detail
