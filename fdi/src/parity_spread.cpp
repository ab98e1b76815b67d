#include "parity_spread.hpp"

#include <algorithm>
#include <cmath>

#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {

namespace {
constexpr int kSearchSteps = 80;  //!< golden-section steps of the likelihood's maximum
}  // namespace

ParitySpread::ParitySpread(double false_alarm)
    : threshold_(std::log(static_cast<double>(design::spread_window_samples) / false_alarm)) {}

void ParitySpread::clear_sums() {
  samples_ = beyond_ = 0;
  sum_capped_ = sum_d_ = sum_below_ = sum_d_below_ = sum_offset_ = 0.0;
}

void ParitySpread::reset() {
  clear_sums();
  ratio_ = measured_ = 1.0;
  checked_ = false;
  start_ns_ = -1;
  epochs_ = checked_samples_ = 0;
}

void ParitySpread::restart() {
  clear_sums();
}

namespace {
//! Hnoise's row: the white noise variance ratio an alarm of `statistic` against `threshold` needs (`chi2`: a
//! χ², else a sum in σ), consistent up to `allowed`.
LedgerRow noise_hypothesis_row(double statistic, double threshold, bool chi2, double allowed) {
  const double excess = statistic / threshold;
  return judge(EvidenceSource::kUncheckedNoise, kHypothesisNoise, chi2 ? excess : excess * excess, allowed,
               allowed);
}
}  // namespace

std::optional<LedgerRow> ParitySpread::noise_row(double statistic, double threshold, bool chi2) const {
  if (checked_) return std::nullopt;
  return noise_hypothesis_row(statistic, threshold, chi2, design::spread_held_ratio);
}

std::optional<SpreadFinding> ParitySpread::observe(double u, int dof, double cap, std::int64_t now_ns,
                                                   double offset) {
  if (start_ns_ < 0) start_ns_ = now_ns;
  epochs_ = std::min(epochs_ + 1, design::spread_hold_epochs);
  if (epochs_ >= design::spread_hold_epochs ||
      now_ns - start_ns_ >= static_cast<std::int64_t>(design::spread_hold_s * 1e9))
    checked_ = true;
  if (!std::isfinite(u) || dof < 1) return std::nullopt;
  checked_samples_ = std::min(checked_samples_ + 1, design::spread_hold_samples);
  if (checked_samples_ >= design::spread_hold_samples) checked_ = true;
  const double d = dof;
  dof_ = dof;
  ++samples_;
  sum_d_ += d;
  sum_offset_ += offset;
  sum_capped_ += std::min(u, cap);
  if (u < cap) {
    sum_below_ += u;
    sum_d_below_ += d;
  } else {
    ++beyond_;
  }
  const double mean = sum_capped_ / (sum_d_ + sum_offset_);
  const double g = 0.5 * sum_d_ * (mean - 1.0 - std::log(mean)) / design::spread_difference_inflation;
  if (g <= threshold_ || samples_ < design::spread_min_samples) {
    if (samples_ >= design::spread_window_samples) clear_sums();
    return std::nullopt;
  }
  SpreadFinding f;
  f.statistic = g;
  f.threshold = threshold_;
  f.samples = samples_;
  f.estimate = estimate(cap);
  const double shown = ratio_ * (f.estimate + interval(f.estimate));
  const double next = std::max(1.0, shown);
  clear_sums();
  if (next == ratio_ || (f.estimate < 1.0 && next > ratio_)) {
    measured_ = std::min(shown, ratio_);
    return std::nullopt;
  }
  ratio_ = next;
  measured_ = std::min(shown, ratio_);
  f.ratio = ratio_;
  return f;
}

double ParitySpread::interval(double estimate) const {
  // u's spread per degree of freedom is about (λ̂ + q̄)·√2 (q̄ the offset's mean).
  return design::spread_interval_sigmas * std::sqrt(2.0 * design::spread_difference_inflation / sum_d_) *
         (estimate + sum_offset_ / sum_d_);
}

double ParitySpread::upper(double cap) const {
  // u·ν/(λ + q̄) ~ χ²_ν with ν = Σd/κ effective degrees of freedom (successive values share a block): the
  // upper end of λ's one-sided interval at design::spread_interval_sigmas is where χ²_ν's lower quantile
  // (Wilson–Hilferty) meets the sums' mean. Few samples bound λ loosely: a model checked by three values has
  // not been checked.
  const double nu = sum_d_ / design::spread_difference_inflation;
  const double spread = std::sqrt(2.0 / (9.0 * nu));
  const double cube = 1.0 - spread * spread - design::spread_interval_sigmas * spread;
  if (cube <= 0.0) return design::spread_held_ratio;
  const double q_mean = sum_offset_ / sum_d_;
  return (estimate(cap) + q_mean) / (cube * cube * cube) - q_mean;
}

LedgerRow ParitySpread::allowed_row(double statistic, double threshold, double cap) const {
  // The largest white noise the sums leave possible (before two samples, what an unchecked model may hide).
  const double allowed =
      samples_ >= 2 ? std::clamp(upper(cap), 1.0, design::spread_held_ratio) : design::spread_held_ratio;
  return noise_hypothesis_row(statistic, threshold, false, allowed);
}

double ParitySpread::estimate(double cap) const {
  if (sum_offset_ > 0.0) return std::max(sum_capped_ - sum_offset_, 1e-3 * sum_d_) / sum_d_;
  if (beyond_ == 0) return sum_below_ / sum_d_below_;
  // ℓ(λ) over ln λ, unimodal: golden-section search between the capped mean's λ and a hundred times it.
  const auto loglik = [&](double log_lambda) {
    const double lambda = std::exp(log_lambda);
    const double tail = std::max(chi2_survival(cap / lambda, dof_), 1e-300);
    return -0.5 * sum_d_below_ * log_lambda - sum_below_ / (2.0 * lambda) + beyond_ * std::log(tail);
  };
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = std::log(std::max(sum_capped_ / sum_d_, 1e-6));
  double hi = lo + std::log(100.0);
  double a = hi - phi * (hi - lo);
  double b = lo + phi * (hi - lo);
  double fa = loglik(a);
  double fb = loglik(b);
  for (int i = 0; i < kSearchSteps; ++i) {
    if (fa < fb) {
      lo = a;
      a = b;
      fa = fb;
      b = lo + phi * (hi - lo);
      fb = loglik(b);
    } else {
      hi = b;
      b = a;
      fb = fa;
      a = hi - phi * (hi - lo);
      fa = loglik(a);
    }
  }
  return std::exp(0.5 * (lo + hi));
}

bool BlockDifferences::add(const double* p, int dof, std::uint32_t mask, bool clean, int block_epochs) {
  if (!clean || mask != mask_ ||
      dof != dof_) {  // the run of blocks is broken: start again from the next epoch
    mask_ = mask;
    dof_ = dof;
    restart();
    if (!clean) return false;
  }
  if (epochs_ == 0) std::fill(sum_.begin(), sum_.begin() + dof, 0.0);
  for (int r = 0; r < dof; ++r) sum_[static_cast<std::size_t>(r)] += p[r];
  if (++epochs_ < block_epochs) return false;
  epochs_ = 0;
  const bool three = blocks_ >= 2;
  u_ = 0.0;
  for (int r = 0; r < dof; ++r) {
    const auto k = static_cast<std::size_t>(r);
    const double second = sum_[k] - 2.0 * last_[k] + before_[k];
    u_ += second * second / (6.0 * block_epochs);
    before_[k] = last_[k];
    last_[k] = sum_[k];
  }
  blocks_ = std::min(blocks_ + 1, 2);
  return three;
}

}  // namespace tetra::fdi::detail
