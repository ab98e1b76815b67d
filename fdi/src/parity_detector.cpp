#include "parity_detector.hpp"

#include <algorithm>
#include <cmath>

namespace tetra::fdi::detail {

ParityDetector::ParityDetector(int n_gyros, double nominal_window_s) : nominal_window_s_(nominal_window_s) {
  const Eigen::Index dmax = std::max(1, n_gyros - 3);
  p_slow_ = Eigen::VectorXd::Zero(dmax);
  mcusum_ = Eigen::VectorXd::Zero(dmax);
  mc_sum_ = Eigen::VectorXd::Zero(dmax);
  p_ema_ = Eigen::VectorXd::Zero(dmax);
  p_ = Eigen::VectorXd::Zero(dmax);
  dp_ = Eigen::VectorXd::Zero(dmax);
}

void ParityDetector::restart(std::int64_t next_index) {
  cusum_mask_ = 0;
  cusum_pos_ = cusum_neg_ = 0.0;
  cusum_pos_start_ = cusum_neg_start_ = next_index;
  mcusum_.setZero();
  mc_sum_.setZero();
  mc_n_ = 0;
  mc_start_ = next_index;
  p_ema_.setZero();
  p_slow_.setZero();
  slow_age_s_ = 0.0;
}

bool ParityDetector::parity_nominal(const Subset& s) const {
  if (s.dof < 1 || slow_age_s_ < nominal_window_s_) return false;
  const auto d = static_cast<Eigen::Index>(s.dof);
  const double var = slow_var_ + s.bias_wander_sigma * s.bias_wander_sigma;
  return p_slow_.head(d).squaredNorm() < s.nominal_threshold * var;
}

void ParityDetector::restart_after_alarm() {
  cusum_pos_ = cusum_neg_ = 0.0;
  mcusum_.setZero();
}

Detection ParityDetector::update(const EpochFrame& frame, const Subset& s, GyroMask active,
                                 double sqrt_period, Health& health) {
  Detection d;
  d.onset_index = frame.index;
  // The χ² sees one sample: with quantization its own whitening (white noise and quantization error).
  double chi2 = apply_parity(s, frame.usable, frame.y_rad_s.data(), sqrt_period, p_.data());
  if (s.quantized)
    chi2 = apply_whitened(s.sample_parity, s.dof, frame.usable, frame.y_rad_s.data(), sqrt_period, dp_.data());
  health.chi2 = chi2;
  health.chi2_threshold = s.chi2_threshold;
  health.parity_residual = s.dof >= 1 ? std::sqrt(chi2) : 0.0;
  if (s.dof >= 1 && chi2 > s.chi2_threshold) d = {true, DetectionTest::kChi2, chi2, frame.index, false};
  if (frame.usable != active || s.dof < 1) return d;

  d.cusum_ran = true;
  if (cusum_mask_ != active) {  // a new gyro set: its CUSUM starts from zero
    cusum_mask_ = active;
    cusum_pos_ = cusum_neg_ = 0.0;
    mcusum_.setZero();
    mc_sum_.setZero();
    mc_n_ = 0;
    p_ema_.setZero();
    p_slow_.setZero();
    slow_age_s_ = 0.0;
  }
  const double alpha = std::min(1.0, frame.dt_s / 2.0);  // EMA time constant 2 s
  for (int r = 0; r < s.dof; ++r) p_ema_[r] += alpha * (p_[r] - p_ema_[r]);
  // The slow mean: white unit-variance input gives an EMA of variance β/(2 − β) in steady state.
  const double beta = std::min(1.0, frame.dt_s / nominal_window_s_);
  for (int r = 0; r < s.dof; ++r) p_slow_[r] += beta * (p_[r] - p_slow_[r]);
  // Quantization: each sample's error term is a difference u_k − u_{k−1} (1σ of u: quantization_sigma), whose
  // EMA telescopes to β²(1 + β(1 − β)²/(2 − β))·σ_u².
  const double qs = s.quantization_sigma;
  slow_var_ = beta / (2.0 - beta) + beta * beta * (1.0 + beta * (1.0 - beta) * (1.0 - beta) / (2.0 - beta)) * qs * qs;
  slow_age_s_ += frame.dt_s;
  std::int64_t onset = d.onset_index;
  const double stat =
      s.dof == 1 ? scalar_cusum(p_[0], s, frame.index, onset) : vector_cusum(s, frame.index, onset);
  health.cusum = stat;
  health.cusum_threshold = s.cusum_h;
  if (stat > s.cusum_h && !d.alarm) {
    d.alarm = true;
    d.test = DetectionTest::kCusum;
    d.statistic = stat;
    d.onset_index = onset;
  }
  return d;
}

double ParityDetector::scalar_cusum(double p, const Subset& s, std::int64_t index, std::int64_t& onset) {
  if (cusum_pos_ <= 0.0) cusum_pos_start_ = index;
  if (cusum_neg_ <= 0.0) cusum_neg_start_ = index;
  cusum_pos_ = std::max(0.0, cusum_pos_ + p - s.cusum_k);
  cusum_neg_ = std::max(0.0, cusum_neg_ - p - s.cusum_k);
  onset = cusum_pos_ >= cusum_neg_ ? cusum_pos_start_ : cusum_neg_start_;
  return std::max(cusum_pos_, cusum_neg_);
}

double ParityDetector::vector_cusum(const Subset& s, std::int64_t index, std::int64_t& onset) {
  // Crosier's multivariate CUSUM: C = |S + p|; S ← 0 if C ≤ k, else (S + p)(1 − k/C).
  const auto d = static_cast<Eigen::Index>(s.dof);
  if (mcusum_.head(d).squaredNorm() == 0.0) {
    mc_start_ = index;
    mc_sum_.setZero();
    mc_n_ = 0;
  }
  dp_.head(d) = mcusum_.head(d) + p_.head(d);
  const double c = dp_.head(d).norm();
  if (c <= s.cusum_k) {
    mcusum_.setZero();
  } else {
    mcusum_.head(d) = dp_.head(d) * (1.0 - s.cusum_k / c);
  }
  mc_sum_.head(d) += p_.head(d);
  ++mc_n_;
  onset = mc_start_;
  return mcusum_.head(d).norm();
}

}  // namespace tetra::fdi::detail
