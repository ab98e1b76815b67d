#include "reference_noise_match.hpp"

#include <algorithm>
#include <cmath>

#include "block_match.hpp"
#include "mekf.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi::detail {

ReferenceNoiseMatch::ReferenceNoiseMatch(const PipelineConfig& config, int gyro_count)
    : false_alarm_(allocated_probability(config, BudgetTest::kReferenceNoiseMatch)),
      window_s_(config.reference_window_s),
      reference_var_(std::pow(config.reference_sigma_arcsec * kArcsecToRad, 2)),
      cusum_(static_cast<std::size_t>(gyro_count), 0.0),
      mean_square_(static_cast<std::size_t>(gyro_count), 0.0),
      block_z_(static_cast<std::size_t>(gyro_count), 0.0),
      block_s_(static_cast<std::size_t>(gyro_count), 0.0),
      matched_(static_cast<std::size_t>(gyro_count), false),
      ratio_(static_cast<std::size_t>(gyro_count), 1.0),
      own_(static_cast<std::size_t>(gyro_count), 1.0) {}

void ReferenceNoiseMatch::reset() {
  mask_ = 0;
  restart_statistics();
  std::fill(matched_.begin(), matched_.end(), false);
  std::fill(ratio_.begin(), ratio_.end(), 1.0);
  std::fill(own_.begin(), own_.end(), 1.0);
  common_ = 1.0;
}

void ReferenceNoiseMatch::restart_statistics() {
  last_ns_ = -1;
  block_samples_ = 0;
  std::fill(cusum_.begin(), cusum_.end(), 0.0);
  std::fill(mean_square_.begin(), mean_square_.end(), 0.0);
  std::fill(block_z_.begin(), block_z_.end(), 0.0);
  std::fill(block_s_.begin(), block_s_.end(), 0.0);
}

std::optional<NoiseFinding> ReferenceNoiseMatch::observe(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                                         const Eigen::Matrix3d& S,
                                                         const Eigen::Matrix3Xd& pinv, GyroMask mask,
                                                         Mekf& filter) {
  if (mask != mask_) {  // other gyros: statistics afresh (a matched gyro keeps its filter noise)
    restart_statistics();
    mask_ = mask;
  }
  const double dt_s = last_ns_ < 0 ? 0.0 : ns_to_seconds(now_ns - last_ns_);
  const bool first = last_ns_ < 0 || dt_s > window_s_;
  if (first) block_start_ns_ = now_ns;
  last_ns_ = now_ns;
  block_samples_ = first ? 1 : block_samples_ + 1;
  const bool close_block = now_ns - block_start_ns_ >= seconds_to_ns(design::reference_match_block_s);
  // A block of n samples stands for n of the per-sample false-alarm probability p.
  // (p·n at most 1/2, so the threshold stays above ln 2 whatever p the configuration allows)
  const double threshold = block_cusum_threshold(false_alarm_ * block_samples_);
  if (close_block) {
    block_start_ns_ = now_ns;
    block_samples_ = 0;
  }
  const double T = std::max(dt_s, 1e-3);
  const double alpha = first ? 1.0 : -std::expm1(-T / window_s_);
  std::optional<NoiseFinding> found;
  for (int i = 0; i < static_cast<int>(cusum_.size()); ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    const auto k = static_cast<std::size_t>(i);
    const double h2 = pinv.col(i).squaredNorm();
    if (!(h2 > 0.0)) continue;
    const Eigen::Vector3d d = pinv.col(i) / std::sqrt(h2);
    const double s = d.dot(S * d);
    if (!(s > 0.0)) continue;
    const double zd = d.dot(z_rad);
    mean_square_[k] = first ? s : mean_square_[k] + alpha * (zd * zd - mean_square_[k]);
    if (first) {
      block_z_[k] = 0.0;
      block_s_[k] = 0.0;
    }
    block_z_[k] += zd;
    block_s_[k] += s;
    if (!close_block) continue;
    const double u = block_z_[k] * block_z_[k] / block_s_[k];
    block_z_[k] = 0.0;
    block_s_[k] = 0.0;
    cusum_[k] = block_cusum_step(cusum_[k], u, 1.0);
    if (matched_[k]) {
      ratio_[k] = std::clamp(ratio_[k] * std::exp(design::block_match_gain * (u - 1.0)), 1.0,
                             design::reference_max_noise_ratio * design::reference_max_noise_ratio);
    } else if (cusum_[k] > threshold) {
      matched_[k] = true;
      filter.add_attitude_variance_along(d, std::max(mean_square_[k] - s, 0.0));
      const double n2 = filter.arw_rad_rts(i + 1) * filter.arw_rad_rts(i + 1);
      ratio_[k] = std::clamp(1.0 + mapped_noise(i, d, h2, T, pinv, mask, filter) / n2, 1.0,
                             design::reference_max_noise_ratio * design::reference_max_noise_ratio);
      if (!found) found = NoiseFinding{i + 1, cusum_[k]};
    }
    apply(k, filter);
  }
  return found;
}

void ReferenceNoiseMatch::apply(std::size_t k, Mekf& filter) const {
  const int id = static_cast<int>(k) + 1;
  const double n2 = filter.arw_rad_rts(id) * filter.arw_rad_rts(id);
  filter.set_added_noise(id, (std::max({matched_[k] ? ratio_[k] : 1.0, own_[k], common_}) - 1.0) * n2);
}

void ReferenceNoiseMatch::set_common_ratio(double ratio, Mekf& filter) {
  common_ = std::clamp(ratio, 1.0, design::reference_max_noise_ratio * design::reference_max_noise_ratio);
  for (std::size_t k = 0; k < own_.size(); ++k) apply(k, filter);
}

void ReferenceNoiseMatch::set_own_ratio(int id, double ratio, Mekf& filter) {
  const auto k = static_cast<std::size_t>(id - 1);
  own_[k] = std::clamp(ratio, 1.0, design::reference_max_noise_ratio * design::reference_max_noise_ratio);
  apply(k, filter);
}

double ReferenceNoiseMatch::mapped_noise(int i, const Eigen::Vector3d& d, double h2, double T,
                                         const Eigen::Matrix3Xd& pinv, GyroMask mask,
                                         const Mekf& filter) const {
  // The step noise along d_i whose steady-state a-priori variance is P.
  const double P = std::max(mean_square_[static_cast<std::size_t>(i)] - reference_var_, 0.0);
  const double q = P * P / ((P + reference_var_) * T);
  double q_model = 0.0;
  for (int j = 0; j < static_cast<int>(cusum_.size()); ++j) {
    if (!has_gyro(mask, j + 1)) continue;
    const double n = filter.arw_rad_rts(j + 1);
    q_model += n * n * std::pow(d.dot(pinv.col(j)), 2);
  }
  return std::max(q - q_model, 0.0) / h2;
}

void ReferenceNoiseMatch::match_all(GyroMask mask) {
  for (std::size_t k = 0; k < matched_.size(); ++k)
    if (has_gyro(mask, static_cast<int>(k) + 1)) matched_[k] = true;
}

void ReferenceNoiseMatch::forget(int id) {
  const auto k = static_cast<std::size_t>(id - 1);
  matched_[k] = false;
  ratio_[k] = 1.0;
  own_[k] = 1.0;
}

}  // namespace tetra::fdi::detail
