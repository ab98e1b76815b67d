#include "reference_consistency.hpp"

#include <algorithm>
#include <cmath>

#include "block_match.hpp"
#include "tetra/core/allan_stats.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi::detail {

namespace {
//! χ²_ν(1 − p) by Wilson–Hilferty, `z` = Φ⁻¹(1 − p): above the exact quantile for small ν at these tails
//! (ν = 3, p = 1e-9: 50.4 against 44.9), within 1 % from ν = 30.
double chi2_upper_wh(double dof, double z) {
  const double v = 2.0 / (9.0 * dof);
  const double c = 1.0 - v + z * std::sqrt(v);
  return dof * c * c * c;
}
}  // namespace

ReferenceConsistency::ReferenceConsistency(const PipelineConfig& config)
    : config_(config),
      jump_chi2_(allan::chi2_quantile(1.0 - allocated_probability(config, BudgetTest::kReferenceCheck), 3.0)),
      lag_chi2_(allan::chi2_quantile(1.0 - allocated_probability(config, BudgetTest::kReferenceCheck), 1.0)),
      mean_accept_chi2_(allan::chi2_quantile(1.0 - design::reference_mean_accept_probability, 3.0)),
      z_tail_(std::sqrt(
          allan::chi2_quantile(1.0 - 2.0 * allocated_probability(config, BudgetTest::kReferenceCheck), 1.0))),
      sigma_config_rad_(config.reference_sigma_arcsec * kArcsecToRad),
      step_(config) {
  reset();
}

void ReferenceConsistency::reset() {
  sigma_rad_ = sigma_config_rad_;
  reopen();
}

void ReferenceConsistency::reopen() {
  state_ = ReferenceState::kAbsent;
  consistent_since_ns_ = 0;
  nis_per_dof_ = 0.0;
  rejected_for_nis_ = false;
  restart();
}

void ReferenceConsistency::restart() {
  block_start_ns_ = -1;
  bias_start_ns_ = -1;
  mean_unresolved_ = false;
  step_.reset();
  last_sample_ns_ = -1;
}

void ReferenceConsistency::restart_blocks(std::int64_t now_ns) {
  lag_den_ = 0.0;
  reaccept_den_ = 0.0;
  block_start_ns_ = now_ns;
  block_count_ = 0;
  block_nis_ = 0.0;
  for (Eigen::Vector3d* v : {&sw_, &swo_, &swz_, &swoo_, &swoz_, &szz_, &sss_}) v->setZero();
  step_.reset();
  restart_bias_block(now_ns);
}

void ReferenceConsistency::restart_bias_block(std::int64_t now_ns) {
  step_.reset();  // the mean matched elsewhere is in no later step either
  bias_start_ns_ = now_ns;
  bias_count_ = 0;
  mean_unresolved_ = false;
  bias_sw_.setZero();
  bias_swz_.setZero();
}

void ReferenceConsistency::accumulate(std::int64_t now_ns, const Eigen::Vector3d& z, const Eigen::Vector3d& w,
                                      double nis, const Eigen::Vector3d& omega,
                                      const Eigen::Vector3d& calibration_rad_s) {
  // Blocks: a new one when the last has run its length (the sample opens the next).
  if (block_start_ns_ < 0 || now_ns - block_start_ns_ > seconds_to_ns(config_.reference_window_s)) {
    if (block_start_ns_ >= 0) reaccept_den_ += lag_den_;
    lag_den_ = 0.0;
    block_start_ns_ = now_ns;
    block_count_ = 0;
    block_nis_ = 0.0;
    for (Eigen::Vector3d* v : {&sw_, &swo_, &swz_, &swoo_, &swoz_, &szz_, &sss_}) v->setZero();
  }
  if (bias_start_ns_ < 0 || now_ns - bias_start_ns_ > seconds_to_ns(design::reference_bias_window_s)) {
    bias_start_ns_ = now_ns;
    bias_count_ = 0;
    bias_sw_.setZero();
    bias_swz_.setZero();
  }
  ++block_count_;
  block_nis_ += nis;
  sw_ += w;
  swo_ += w.cwiseProduct(omega);
  swz_ += w.cwiseProduct(z);
  swoo_ += w.cwiseProduct(omega).cwiseProduct(omega);
  swoz_ += w.cwiseProduct(omega).cwiseProduct(z);
  ++bias_count_;
  bias_sw_ += w;
  bias_swz_ += w.cwiseProduct(z);
  nis_per_dof_ = block_nis_ / (3.0 * block_count_);
  const double since_s = last_sample_ns_ < 0 ? 0.0 : ns_to_seconds(now_ns - last_sample_ns_);
  last_sample_ns_ = now_ns;
  step_.add(z, w.cwiseInverse(), sigma_rad_ * sigma_rad_, calibration_rad_s * since_s, since_s);
}

std::optional<ReferenceCheck> ReferenceConsistency::test(std::int64_t now_ns, const Eigen::Vector3d& z,
                                                         const Eigen::Vector3d& w, double nis,
                                                         const Eigen::Vector3d& omega,
                                                         const Eigen::Vector3d& calibration_rad_s,
                                                         double& bias_statistic) {
  accumulate(now_ns, z, w, nis, omega, calibration_rad_s);
  const double dof = 3.0 * block_count_;
  // Lag: z = a − ω·τ with a per-axis offset a; τ̂ = −num/den, var(τ̂) = 1/den.
  double num = 0.0;
  double den = 0.0;
  for (int a = 0; a < 3; ++a) {
    num += swoz_[a] - swo_[a] * swz_[a] / sw_[a];
    den += swoo_[a] - swo_[a] * swo_[a] / sw_[a];
  }
  const bool lag = block_count_ >= 3 && den > 0.0 && num * num / den > lag_chi2_;
  // A late reference also put ω̄·τ̂ in the attitude while the rate was steady (it looks like an offset then).
  lag_offset_rad_.setZero();
  lag_den_ = std::max(den, 0.0);
  lag_s_ = den > 0.0 ? -num / den : 0.0;
  if (den > 0.0) lag_offset_rad_ = (swo_.cwiseQuotient(sw_) * lag_s_).cwiseAbs();
  const bool nis_high = block_nis_ > chi2_upper_wh(dof, z_tail_);
  // A lag shows as a jump when a slew starts and as a raised NIS: it is named when its own test holds.
  if (nis > jump_chi2_) {
    // One sample far off: a lag only if the fitted lag explains this sample too (a mis-identification
    // during a rate change is not a lag).
    failed_ = {nis, jump_chi2_, 3};
    if (!lag) return ReferenceCheck::kJump;
    double residual = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double offset = (swz_[a] + lag_s_ * swo_[a]) / sw_[a];
      const double r = z[a] - (offset - omega[a] * lag_s_);
      residual += r * r * w[a];
    }
    failed_ = {residual, jump_chi2_, 3};
    if (residual > jump_chi2_) return ReferenceCheck::kJump;
  }
  if (lag) {
    failed_ = {num * num / den, lag_chi2_, 1};
    return ReferenceCheck::kLag;
  }
  if (nis_high) {
    failed_ = {block_nis_, chi2_upper_wh(dof, z_tail_), static_cast<int>(dof)};
    return ReferenceCheck::kNis;
  }
  // The long mean before the step: a mean the drift match explains is not a step (the caller's arbiter
  // judges a step with a mean beyond the match's level as the mean it is).
  const double bias = mean_innovation_chi2(bias_sw_, bias_swz_);
  bias_statistic = bias;
  mean_unresolved_ = bias > mean_accept_chi2_;
  if (bias > jump_chi2_) {
    failed_ = {bias, jump_chi2_, 3};
    return ReferenceCheck::kBias;
  }
  step_fit_ = step_.evaluate(step_.threshold());
  if (step_fit_.statistic > step_.threshold()) {
    failed_ = {step_fit_.statistic, step_.threshold(), 3};
    return ReferenceCheck::kStep;
  }
  failed_ = {bias, jump_chi2_, 3};
  return std::nullopt;
}

bool ReferenceConsistency::reestimate_noise(std::int64_t now_ns, const Eigen::Vector3d& z) {
  // Evaluated once a block (reference_window_s), over every rejected sample since the rejection. The
  // difference of successive innovations: the reference's white noise twice (2σ² per axis), the
  // attitude's error changing over one sample interval (the gyros' noise and bias error over ~1 s: far below
  // an arcsecond), so the estimate does not depend on how loose the gyro-propagated attitude has become. A
  // steady drift of that error is a mean of the differences, removed per axis.
  if (have_last_z_) {
    const Eigen::Vector3d d = z - last_z_;
    noise_sum_ += d;
    noise_sum_sq_ += d.cwiseProduct(d);
    ++noise_count_;
  }
  last_z_ = z;
  have_last_z_ = true;
  if (now_ns - noise_start_ns_ < seconds_to_ns(config_.reference_window_s) || noise_count_ < 4) return false;
  const double k = noise_count_;
  const double var_d_rad2 =
      (noise_sum_sq_ - noise_sum_.cwiseProduct(noise_sum_) / k).sum() / (3.0 * (k - 1.0));
  // Successive differences share a sample (correlation −1/2): counted as half as many independent squares,
  // the upper bound at 1 − 1e-3 of σ² = var(d)/2 is ν·σ̂²/χ²_ν(1e-3) with ν = 3(k − 1)/2.
  const double dof = 1.5 * (k - 1.0);
  const double estimate_rad2 = 0.5 * std::max(var_d_rad2, 0.0);
  const double upper_rad = std::sqrt(estimate_rad2 * dof / allan::chi2_quantile(1e-3, dof));
  const double lower_rad = std::sqrt(estimate_rad2 * dof / allan::chi2_quantile(1.0 - 1e-3, dof));
  noise_start_ns_ = now_ns;  // the next evaluation a block later, over every difference since the rejection
  // Noise explains the rejection only if the samples are shown noisier than configured (the lower bound
  // above it): a step or a drift of the reference raises the NIS, not the differences, and stays rejected.
  // Beyond reference_noise_max_factor it is not the sensor its configuration describes: rejected too.
  noise_explained_ =
      lower_rad > sigma_config_rad_ && upper_rad <= design::reference_noise_max_factor * sigma_config_rad_;
  if (!noise_explained_) return false;
  const bool grew = upper_rad > sigma_rad_;
  // More differences tighten the bound: a smaller σ (never below the configured one) needs no new start.
  sigma_rad_ = std::max(upper_rad, sigma_config_rad_);
  return grew;
}

ReferenceEvidence ReferenceConsistency::test_sample(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                                    const Eigen::Matrix3d& S,
                                                    const Eigen::Vector3d& omega_rad_s,
                                                    const Eigen::Vector3d& calibration_rad_s,
                                                    bool steps_judged) {
  if (!steps_judged) step_.reset();
  const double nis = z_rad.dot(S.ldlt().solve(z_rad));
  const Eigen::Vector3d w = S.diagonal().cwiseInverse();
  ReferenceEvidence e;
  e.used_excess_rad2 = szz_ - sss_;  // before the sample (which may open the next block)
  e.used_count = block_start_ns_ < 0 ? 0 : block_count_;
  e.failed = test(now_ns, z_rad, w, nis, omega_rad_s, calibration_rad_s, e.bias_statistic);
  if (e.failed == ReferenceCheck::kStep) e.ramp = step_.ramp_fit();
  return e;
}

ReferenceVerdict ReferenceConsistency::decide(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                              const Eigen::Matrix3d& S, const ReferenceEvidence& evidence,
                                              ReferenceDecision decision, double drift_threshold) {
  if (state_ == ReferenceState::kRejected) return judge_rejected(now_ns, z_rad, S, evidence.failed);
  state_ = ReferenceState::kAccepted;
  ReferenceVerdict v;
  switch (decision) {
    case ReferenceDecision::kMatchDrift:
      // The caller opens the gyros' bias model — at the match's level, below the rejection's, since a match
      // decides nothing — and the sample is used; the bias block starts afresh.
      v.drift = true;
      v.from_ramp = evidence.failed == ReferenceCheck::kStep && evidence.ramp;
      v.bias_mean_rad = v.from_ramp ? Eigen::Vector3d(0.5 * evidence.ramp->span_s * evidence.ramp->rate_rad_s)
                                    : bias_mean_rad();
      v.bias_span_s = v.from_ramp ? evidence.ramp->span_s : ns_to_seconds(now_ns - bias_start_ns_);
      drift_check_ = v.from_ramp ? failed_ : CheckValue{evidence.bias_statistic, drift_threshold, 3};
      restart_bias_block(now_ns);
      add_used(z_rad, S);
      return v;
    case ReferenceDecision::kUse:
      add_used(z_rad, S);
      return v;
    case ReferenceDecision::kNoCall:
      v.inconsistent = evidence.failed;
      restart_blocks(now_ns);  // reported once per failure, then judged afresh
      return v;
    case ReferenceDecision::kReject:
      break;
  }
  if (!evidence.failed) {  // (rows that reject without a failed test: none are written; used as it is)
    add_used(z_rad, S);
    return v;
  }
  // Rejected: what the samples used in this block may have put in the attitude beyond what the filter
  // assumed is their innovations' second moment beyond the predicted one.
  if (evidence.used_count > 0)
    v.contamination_rad2 = (evidence.used_excess_rad2 / evidence.used_count).cwiseMax(0.0);
  if (*evidence.failed == ReferenceCheck::kLag)
    v.contamination_rad2 += lag_offset_rad_.cwiseProduct(lag_offset_rad_);
  if (*evidence.failed == ReferenceCheck::kStep) {
    // The share of the step the filter has taken is in the attitude; the rest is in the samples to come.
    const Eigen::Vector3d taken = step_fit_.step_rad.cwiseProduct(step_fit_.absorbed);
    v.contamination_rad2 += taken.cwiseProduct(taken);
    v.step_rad = step_fit_.step_rad.norm();
  }
  v.use = false;
  v.rejected = evidence.failed;
  reject(now_ns, *evidence.failed);
  return v;
}

void ReferenceConsistency::add_used(const Eigen::Vector3d& z_rad, const Eigen::Matrix3d& S) {
  szz_ += z_rad.cwiseProduct(z_rad);
  sss_ += S.diagonal();
}

void ReferenceConsistency::reject(std::int64_t now_ns, ReferenceCheck why) {
  state_ = ReferenceState::kRejected;
  rejected_lag_s_ = why == ReferenceCheck::kLag ? std::abs(lag_s_) : 0.0;
  rejected_for_nis_ = why == ReferenceCheck::kNis;
  noise_start_ns_ = now_ns;
  noise_sum_.setZero();
  noise_sum_sq_.setZero();
  noise_count_ = 0;
  have_last_z_ = false;
  noise_explained_ = false;
  restart_blocks(now_ns);
  consistent_since_ns_ = now_ns + 1;  // from the next sample on
}

ReferenceVerdict ReferenceConsistency::judge_rejected(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                                      const Eigen::Matrix3d& S,
                                                      const std::optional<ReferenceCheck>& failed) {
  ReferenceVerdict v;
  v.use = false;
  if ((rejected_for_nis_ && reestimate_noise(now_ns, z_rad)) || failed) {
    // Judged again from the next sample on (after a new noise estimate, against the new σ).
    restart_blocks(now_ns);
    consistent_since_ns_ = now_ns + 1;
    return v;
  }
  // A reference rejected as late is used again only once the samples since could have shown half that lag
  // (the rate changed enough): at a steady rate a lag is an offset no test sees.
  const double half_lag = 0.5 * rejected_lag_s_;
  const bool lag_seen = half_lag == 0.0 || (reaccept_den_ + lag_den_) * half_lag * half_lag >= lag_chi2_;
  // ...and only while the attitude is known at least as well as the reference claims to know it, so the
  // tests can tell a reference twice as noisy (a looser attitude makes any reference look consistent).
  // (After a `nis` rejection the noise estimate, which needs no tight attitude, tells it instead.)
  const bool tests_see =
      S.trace() / 3.0 <= 2.0 * sigma_rad_ * sigma_rad_ || (rejected_for_nis_ && noise_explained_);
  if (now_ns - consistent_since_ns_ >= seconds_to_ns(config_.reference_window_s) && lag_seen && tests_see) {
    state_ = ReferenceState::kAccepted;
    v.use = true;
    v.reaccepted = true;
    restart_blocks(now_ns);
  }
  return v;
}

}  // namespace tetra::fdi::detail
