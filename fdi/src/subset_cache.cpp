#include "subset_cache.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "tetra/core/units.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {

double bias_wander_sigma(double bias_instability_rad_s, double rate_random_walk_rad_s_rts, double horizon_s) {
  const double b = kBiasWanderPerB * bias_instability_rad_s;
  const double k = rate_random_walk_rad_s_rts;
  return std::sqrt(b * b + k * k * horizon_s);
}

SubsetCache::SubsetCache(GyroGeometry geometry, Eigen::VectorXd bias_sigma_rad_s,
                         const PipelineConfig& config, Eigen::VectorXd bias_wander_rad_s)
    : geometry_(std::move(geometry)),
      bias_sigma_rad_s_(std::move(bias_sigma_rad_s)),
      bias_wander_rad_s_(std::move(bias_wander_rad_s)),
      config_(&config) {
  if (bias_wander_rad_s_.size() != geometry_.gyro_count())
    bias_wander_rad_s_ = Eigen::VectorXd::Zero(gyro_count());
  subsets_.reserve(gyro_count() <= 8 ? 512 : 4096);
}

void SubsetCache::prepare(double period_s) {
  period_s_ = period_s;
  sqrt_period_ = std::sqrt(period_s);
  const int n = gyro_count();
  if (n <= 8) {
    for (GyroMask m = 0; m <= all_gyros(n); ++m) (void)get(m);
  } else {
    (void)get(all_gyros(n));
    for (int id = 1; id <= n; ++id) (void)get(without_gyro(all_gyros(n), id));
  }
}

const Subset& SubsetCache::insert(GyroMask mask) {
  Subset& s = subsets_[mask];
  build(s, mask);
  return s;
}

const Subset* SubsetCache::find(GyroMask mask) const {
  const auto it = subsets_.find(mask);
  return it == subsets_.end() ? nullptr : &it->second;
}

double SubsetCache::parity_bias_sigma(const Subset& s, GyroMask mask) const {
  // The wandering biases b move the parity by √T·W·b: per axis, the mean variance trace(W Σ_b Wᵀ)/d.
  double var = 0.0;
  for (Eigen::Index i = 0; i < s.parity.cols(); ++i) {
    if (!has_gyro(mask, static_cast<int>(i) + 1)) continue;
    const double b = bias_wander_rad_s_[i] * sqrt_period_;
    var += s.parity.col(i).squaredNorm() * b * b;
  }
  return std::sqrt(var / s.dof);
}

void SubsetCache::build(Subset& s, GyroMask mask) const {
  const int n = gyro_count();
  s.mask = mask;
  s.observable = geometry_.observable(mask);
  s.pinv = Eigen::Matrix3Xd::Zero(3, n);
  s.arw_sq_rad2_s.setZero();
  s.bias_sigma_rad_s.setZero();
  if (!s.observable) return;
  s.pinv = *geometry_.pseudoinverse(mask);
  s.arw_sq_rad2_s = *geometry_.noise_variance_per_axis(mask);
  for (int a = 0; a < 3; ++a) {
    double v = 0.0;
    for (int i = 0; i < n; ++i) {
      const double b = bias_sigma_rad_s_[i];
      v += s.pinv(a, i) * s.pinv(a, i) * b * b;
    }
    s.bias_sigma_rad_s[a] = std::sqrt(v);
  }
  s.dof = tetra::gyro_count(mask) - 3;
  if (s.dof < 1) {
    s.parity = Eigen::MatrixXd::Zero(0, n);
    return;
  }
  // Unit-weight parity V (V H = 0, V Vᵀ = I) whitened by the noise: cov(V y) = V R Vᵀ = L Lᵀ, W = L⁻¹ V.
  const Eigen::MatrixXd v = *geometry_.parity_matrix(mask);
  const Eigen::VectorXd& arw = geometry_.sigma();
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) r(i, i) = arw[i] * arw[i];
  const Eigen::MatrixXd cov = v * r * v.transpose();
  const Eigen::LLT<Eigen::MatrixXd> llt(cov);
  s.parity = llt.matrixL().solve(v);
  const PipelineConfig& config = *config_;
  s.chi2_threshold = chi2_threshold(config.chi2_false_alarm_probability, s.dof);
  s.jump_threshold = chi2_threshold(config.jump_false_alarm_probability, s.dof);
  s.nominal_threshold = chi2_threshold(1e-3, s.dof);
  // Smallest parity shift [σ] a step of cusum_min_fault_dps on any gyro of the subset produces.
  double min_col = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    if (has_gyro(mask, i + 1)) min_col = std::min(min_col, s.parity.col(i).norm());
  }
  const double delta = config.cusum_min_fault_dps * kDegToRad * min_col * sqrt_period_;
  s.cusum_k = 0.5 * delta;
  s.bias_wander_sigma = parity_bias_sigma(s, mask);
  s.cusum_h = cusum_threshold(s.dof, s.cusum_k, config.cusum_arl0_epochs, s.bias_wander_sigma);
  if (s.dof >= 2) {
    s.glt_accept = chi2_threshold(1e-3, s.dof - 1);
    s.glt_reject = chi2_threshold(config.glt_false_alarm_probability, s.dof - 1);
  }
}

}  // namespace tetra::fdi::detail
