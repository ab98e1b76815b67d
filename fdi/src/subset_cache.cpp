#include "subset_cache.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {

namespace {}  // namespace

double bias_wander_sigma(double bias_instability_rad_s, double rate_random_walk_rad_s_rts, double horizon_s) {
  const double b = kBiasWanderPerB * bias_instability_rad_s;
  const double k = rate_random_walk_rad_s_rts;
  return std::sqrt(b * b + k * k * horizon_s);
}

DetectorNoise detector_noise(const Calibration& cal, const PipelineConfig& config) {
  const Eigen::Index n = cal.gyro_count();
  DetectorNoise out{Eigen::VectorXd::Zero(n),    Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n),
                    Eigen::VectorXd::Zero(n),    Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n),
                    Eigen::Matrix3Xd::Zero(3, n)};
  for (Eigen::Index i = 0; i < n; ++i) {
    const GyroCalibration& g = cal.gyros[static_cast<std::size_t>(i)];
    if (g.sigma) {  // a log already in deg/s has no scale factor to be wrong (`raw_units_dps`)
      if (!config.raw_units_dps)
        out.scale_rel_sigma[i] = g.sigma->scale_factor_V_per_dps / std::abs(g.scale_factor_V_per_dps);
      out.axis_sigma.col(i) = g.sigma->axis.cwiseAbs();
    }
    const auto& noise = g.noise;
    if (!noise) continue;
    out.quantization_rad[i] = noise->quantization_deg.value_or(0.0) * kDegToRad;
    const double b = noise->bias_instability_dps.value_or(0.0) * kDegToRad;
    const double k = noise->rate_random_walk_dps_per_rts.value_or(0.0) * kDegToRad;
    const double r = noise->rate_ramp_dps_per_s.value_or(0.0) * kDegToRad;
    out.bias_wander_rad_s[i] = bias_wander_sigma(b, k, config.rate_random_walk_horizon_s);
    out.ramp_bound_rad_s[i] = std::abs(r) * config.rate_random_walk_horizon_s;
    out.rate_random_walk_rad_s_rts[i] = k;
    out.rate_ramp_rad_s2[i] = std::abs(r);
  }
  return out;
}

SubsetCache::SubsetCache(GyroGeometry geometry, Eigen::VectorXd bias_sigma_rad_s,
                         const PipelineConfig& config, DetectorNoise noise)
    : geometry_(std::move(geometry)),
      bias_sigma_rad_s_(std::move(bias_sigma_rad_s)),
      quantization_rad_(std::move(noise.quantization_rad)),
      bias_wander_rad_s_(std::move(noise.bias_wander_rad_s)),
      ramp_bound_rad_s_(std::move(noise.ramp_bound_rad_s)),
      rrw_rad_s_rts_(std::move(noise.rate_random_walk_rad_s_rts)),
      ramp_rad_s2_(std::move(noise.rate_ramp_rad_s2)),
      scale_rel_sigma_(std::move(noise.scale_rel_sigma)),
      axis_sigma_(std::move(noise.axis_sigma)),
      config_(&config) {
  if (quantization_rad_.size() != geometry_.gyro_count())
    quantization_rad_ = Eigen::VectorXd::Zero(gyro_count());
  if (bias_wander_rad_s_.size() != geometry_.gyro_count())
    bias_wander_rad_s_ = Eigen::VectorXd::Zero(gyro_count());
  if (ramp_bound_rad_s_.size() != geometry_.gyro_count())
    ramp_bound_rad_s_ = Eigen::VectorXd::Zero(gyro_count());
  if (rrw_rad_s_rts_.size() != geometry_.gyro_count()) rrw_rad_s_rts_ = Eigen::VectorXd::Zero(gyro_count());
  if (ramp_rad_s2_.size() != geometry_.gyro_count()) ramp_rad_s2_ = Eigen::VectorXd::Zero(gyro_count());
  if (scale_rel_sigma_.size() != geometry_.gyro_count())
    scale_rel_sigma_ = Eigen::VectorXd::Zero(gyro_count());
  if (axis_sigma_.cols() != geometry_.gyro_count()) axis_sigma_ = Eigen::Matrix3Xd::Zero(3, gyro_count());
  calibration_sigma_ = (scale_rel_sigma_.array() > 0.0).any() || (axis_sigma_.array() > 0.0).any() ||
                       (bias_sigma_rad_s_.array() > 0.0).any();
  subsets_.reserve(gyro_count() <= 8 ? 512 : 4096);
  if (gyro_count() <= 8) by_mask_.assign(std::size_t{1} << static_cast<unsigned>(gyro_count()), nullptr);
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

void SubsetCache::set_noise_ratios(double white, double sample) {
  white_scale_ = std::sqrt(white);
  sample_ratio_ = sample;
  // In place: the detectors keep references to the subsets, which stay where they are.
  if (ready())
    for (auto& [mask, s] : subsets_) build(s, mask);
}

double SubsetCache::block_quantization(const Subset& s, int m) const {
  double sum = 0.0;
  for (int i = 0; i < gyro_count(); ++i) {
    if (has_gyro(s.mask, i + 1))
      sum += s.parity_col_norm[i] * s.parity_col_norm[i] * quantization_rad_[i] * quantization_rad_[i];
  }
  return 20.0 * sum / (period_s_ * 6.0 * m);
}

double SubsetCache::quantization_share() const {
  double share = 0.0;
  for (int i = 0; i < gyro_count(); ++i) {
    const double total = sample_variance(geometry_.sigma()[i], quantization_rad_[i], period_s_);
    const double white = sample_variance(geometry_.sigma()[i], 0.0, period_s_);
    if (total > 0.0) share = std::max(share, 1.0 - white / total);
  }
  return share;
}

const Subset& SubsetCache::insert(GyroMask mask) {
  Subset& s = subsets_[mask];
  build(s, mask);
  if (mask < by_mask_.size()) by_mask_[mask] = &s;
  return s;
}

const Subset* SubsetCache::find(GyroMask mask) const {
  const auto it = subsets_.find(mask);
  return it == subsets_.end() ? nullptr : &it->second;
}

CusumDesign SubsetCache::track_wander(Subset& s, GyroMask mask, const CusumDesign& bounded) const {
  s.wander_step_var = 0.0;
  s.wander_relief = 0.0;
  // Tracked: a stated rate random walk beyond the average's reach, and any stated rate ramp (R·t has no
  // bound); the tracker takes a ramp as the random walk that reaches R·H at the horizon H, K_R² = R²·H, and
  // lags it by √(T/H) of one sample's σ at most.
  const double horizon_s = config_->rate_random_walk_horizon_s;
  double q = 0.0, ramp = 0.0, ramp_bound = 0.0, stationary = 0.0;
  bool walks = false;
  for (Eigen::Index i = 0; i < s.parity.cols(); ++i) {
    if (!has_gyro(mask, static_cast<int>(i) + 1)) continue;
    const double w2 = s.parity.col(i).squaredNorm();
    const double k2 = rrw_rad_s_rts_[i] * rrw_rad_s_rts_[i];
    const double r2 = ramp_rad_s2_[i] * ramp_rad_s2_[i] * horizon_s;
    walks |= k2 > 0.0 && !bounded.averaged;
    q += w2 * ((bounded.averaged ? 0.0 : k2) + r2) * period_s_ * period_s_ * period_s_;
    ramp += s.parity_col_norm[i] * ramp_rad_s2_[i] * sqrt_period_ * period_s_;
    ramp_bound += s.parity_col_norm[i] * ramp_bound_rad_s_[i] * sqrt_period_;
    // The bias instability's stationary wander, which the tracker is not told of: averaged in h (the
    // random walk's share too while it is within the average's reach).
    const double wander2 = bias_wander_rad_s_[i] * bias_wander_rad_s_[i];
    stationary += w2 * period_s_ * (bounded.averaged ? wander2 : std::max(0.0, wander2 - k2 * horizon_s));
  }
  q /= s.dof;
  if (!(q > 0.0) || (!walks && !(ramp > 0.0))) return bounded;  // bias instability alone: no tracker
  const CusumDesign design = cusum_design(s.dof, s.cusum_k, cusum_arl0_epochs(*config_),
                                          std::sqrt(stationary / s.dof), config_->calibration_error_sigmas);
  // The steady state of the scalar tracker of a random walk (step variance q) in unit white noise: predicted
  // variance P⁻ = (q + √(q² + 4q))/2, gain g = P⁻/(1 + P⁻); it lags a ramp of r per epoch by r(1 − g)/g.
  const double p_pred = 0.5 * (q + std::sqrt(q * q + 4.0 * q));
  const double gain = p_pred / (1.0 + p_pred);
  s.wander_step_var = q;
  s.wander_relief = std::max(0.0, ramp_bound + bounded.k - design.k - ramp * (1.0 - gain) / gain);
  return design;
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

Eigen::MatrixXd SubsetCache::whiten(const Eigen::MatrixXd& v, const Eigen::VectorXd& r) const {
  const Eigen::Index n = r.size();
  Eigen::MatrixXd rm = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) rm(i, i) = r[i];
  const Eigen::MatrixXd cov = v * rm * v.transpose();
  const Eigen::LLT<Eigen::MatrixXd> llt(cov);
  return llt.matrixL().solve(v);
}

void SubsetCache::add_quantization(Subset& s, const Eigen::MatrixXd& v, GyroMask mask) const {
  s.quantized = false;
  for (int i = 0; i < gyro_count(); ++i) s.quantized |= has_gyro(mask, i + 1) && quantization_rad_[i] > 0.0;
  s.sample_parity = s.parity;
  s.jump_parity = s.parity;
  s.quantization_margin = s.quantization_sigma = 0.0;
  if (!s.quantized) return;
  // R·T per gyro for one sample and for half a one-sample difference (p = √T·W·Δy/√2 in the jump test).
  const Eigen::VectorXd arw = geometry_.sigma() * white_scale_;
  Eigen::VectorXd r_sample(gyro_count());
  Eigen::VectorXd r_jump(gyro_count());
  for (int i = 0; i < gyro_count(); ++i) {
    // The larger of what one sample's spread shows (the stated noise times sample_ratio_) and what the white
    // noise taken gives with the stated quantization.
    const double stated_arw = arw[i] / white_scale_;
    r_sample[i] = std::max(sample_ratio_ * sample_variance(stated_arw, quantization_rad_[i], period_s_),
                           sample_variance(arw[i], quantization_rad_[i], period_s_)) *
                  period_s_;
    r_jump[i] =
        0.5 *
        std::max(sample_ratio_ * sample_difference_variance(stated_arw, quantization_rad_[i], period_s_),
                 sample_difference_variance(arw[i], quantization_rad_[i], period_s_)) *
        period_s_;
  }
  s.sample_parity = whiten(v, r_sample);
  s.jump_parity = whiten(v, r_jump);
  s.quantization_margin = quantization_margin(s, mask, s.cusum_k);
  double var = 0.0;
  for (int i = 0; i < gyro_count(); ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    const double bound = quantization_bound(s, i);
    var += bound * bound / 3.0;
  }
  s.quantization_sigma = std::sqrt(var / s.dof);
}

double SubsetCache::quantization_bound(const Subset& s, int i) const {
  return s.parity.col(i).norm() * std::sqrt(3.0) * quantization_rad_[i] / sqrt_period_;
}

double SubsetCache::quantization_margin(const Subset& s, GyroMask mask, double k) const {
  // A sum of samples carries the quantization error of its last sample minus that of the one before its
  // first, W·(e_n − e_m)/√T, e_i uniform within ±√3·Q_i. The CUSUM lingers near h for many epochs, each with
  // a fresh e_n, so the last term reaches its bound U = Σ_i |W_i|·√3·Q_i/√T; the first is one draw, whose
  // effect on the crossing rate ∝ exp(−2k·h) is its moment generating function at 2k:
  // Σ_i ln(sinh x_i / x_i)/(2k), x_i = 2k·|W_i|·√3·Q_i/√T. h is raised by their sum (|W_i|, the column's
  // norm, bounds its projection on any direction for d ≥ 2). Zero for a unit without quantization.
  if (!s.quantized) return 0.0;
  double u = 0.0;
  double log_mgf = 0.0;
  for (int i = 0; i < gyro_count(); ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    const double bound = quantization_bound(s, i);
    const double x = 2.0 * k * bound;
    u += bound;
    if (x > 0.0) log_mgf += std::log(std::sinh(x) / x);
  }
  return u + log_mgf / (2.0 * k);
}

void SubsetCache::build(Subset& s, GyroMask mask) const {
  const int n = gyro_count();
  s.mask = mask;
  s.observable = geometry_.observable(mask);
  s.pinv = Eigen::Matrix3Xd::Zero(3, n);
  s.arw_sq_rad2_s.setZero();
  s.bias_sigma_rad_s.setZero();
  s.parity_col_norm = Eigen::VectorXd::Zero(n);
  if (!s.observable) return;
  s.pinv = *geometry_.pseudoinverse(mask);
  s.arw_sq_rad2_s = *geometry_.noise_variance_per_axis(mask) * (white_scale_ * white_scale_);
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
    s.parity = s.sample_parity = s.jump_parity = Eigen::MatrixXd::Zero(0, n);
    return;
  }
  // Unit-weight parity V (V H = 0, V Vᵀ = I) whitened by the white noise: cov(V y) = V R Vᵀ/T = L Lᵀ/T,
  // W = L⁻¹ V, R = diag(N_i²) (p = √T·W·y ~ N(0, I) without quantization).
  const Eigen::MatrixXd v = *geometry_.parity_matrix(mask);
  const Eigen::VectorXd arw = geometry_.sigma() * white_scale_;
  s.parity = whiten(v, arw.cwiseProduct(arw));
  for (int i = 0; i < n; ++i) {
    if (has_gyro(mask, i + 1)) s.parity_col_norm[i] = s.parity.col(i).norm();
  }
  const PipelineConfig& config = *config_;
  s.chi2_threshold = chi2_threshold(allocated_probability(config, BudgetTest::kChi2), s.dof);
  s.jump_threshold = chi2_threshold(allocated_probability(config, BudgetTest::kJump), s.dof);
  s.spread_threshold = chi2_threshold(allocated_probability(config, BudgetTest::kParitySpread), s.dof);
  s.nominal_threshold = chi2_threshold(1e-3, s.dof);
  // Smallest parity shift [σ] a step of cusum_min_fault_dps on any gyro of the subset produces.
  double min_col = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    if (has_gyro(mask, i + 1)) min_col = std::min(min_col, s.parity.col(i).norm());
  }
  const double delta = config.cusum_min_fault_dps * kDegToRad * min_col * sqrt_period_;
  s.cusum_k = 0.5 * delta;
  add_quantization(s, v, mask);
  s.bias_wander_sigma = parity_bias_sigma(s, mask);
  s.calibration_bias_bound = 0.0;
  for (int i = 0; i < n; ++i) {
    if (has_gyro(mask, i + 1)) s.calibration_bias_bound += s.parity_col_norm[i] * bias_sigma_rad_s_[i];
  }
  s.calibration_bias_bound *= config.calibration_error_sigmas * sqrt_period_;
  for (int i = 0; i < n; ++i) {  // the stated ramps over the horizon, each of either sign
    if (has_gyro(mask, i + 1))
      s.calibration_bias_bound += s.parity_col_norm[i] * ramp_bound_rad_s_[i] * sqrt_period_;
  }
  // A stated wander whose average would reach the reference (a large rate random walk) is a tolerance
  // instead: e·s joins the bound D, which the χ²'s dead zone, the CUSUMs' reference and the protection
  // level carry, where that reaches the design shift sooner (detectors.hpp, cusum_design).
  const CusumDesign design = cusum_design(s.dof, s.cusum_k, cusum_arl0_epochs(config), s.bias_wander_sigma,
                                          config.calibration_error_sigmas);
  s.wander_averaged = design.averaged;
  s.calibration_bias_bound += design.k - s.cusum_k;
  s.cusum_h = track_wander(s, mask, design).h + s.quantization_margin;
  const double averaged_wander = s.wander_averaged ? s.bias_wander_sigma : 0.0;
  // The held level (mean of M epochs over isolation_window_s) misses the episode's true level by N(0, 1/M)
  // per axis, a constant offset for the level test: its reference k grows by design::level_margin_sigmas/√M,
  // which absorbs such an offset (a larger one, rarer than 3σ, only hastens the test's false alarms in that
  // episode).
  s.level_epochs = std::max(2, static_cast<int>(std::lround(design::isolation_window_s / period_s_)));
  s.level_k = s.cusum_k + design::level_margin_sigmas / std::sqrt(static_cast<double>(s.level_epochs));
  s.level_h = cusum_threshold(s.dof, s.level_k, cusum_arl0_epochs(config), averaged_wander) +
              quantization_margin(s, mask, s.level_k);
  if (s.dof >= 2) {
    s.glt_accept = chi2_threshold(1e-3, s.dof - 1);
    s.glt_reject = chi2_threshold(allocated_probability(config, BudgetTest::kGlt), s.dof - 1);
  }
}

void SubsetCache::rate_coefficient_covariance(const Subset& s, GyroMask mask, Eigen::MatrixXd& out) const {
  const int d = s.dof;
  out.setZero(3 * d, 3 * d);
  if (d < 1 || !calibration_sigma_) return;
  const double e = config_->calibration_error_sigmas;
  for (int i = 0; i < gyro_count(); ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    const Eigen::Vector3d h = geometry_.axes_B().row(i).transpose();
    Eigen::Matrix3d g = scale_rel_sigma_[i] * scale_rel_sigma_[i] * h * h.transpose();
    g.diagonal() += axis_sigma_.col(i).cwiseAbs2();
    g *= e * e * period_s_;
    for (int j = 0; j < d; ++j)
      for (int k = 0; k < d; ++k) out.block<3, 3>(3 * j, 3 * k) += s.parity(j, i) * s.parity(k, i) * g;
  }
}

void SubsetCache::calibration_covariance(const Subset& s, GyroMask mask, const Eigen::Vector3d& omega_rad_s,
                                         bool with_bias, Eigen::MatrixXd& out) const {
  out.setZero(s.dof, s.dof);
  if (s.dof < 1) return;
  const double e = config_->calibration_error_sigmas;
  const Eigen::Vector3d omega_sq = omega_rad_s.cwiseAbs2();
  for (int i = 0; i < gyro_count(); ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    const double along = geometry_.axes_B().row(i).dot(omega_rad_s);
    const double b = with_bias ? bias_sigma_rad_s_[i] : 0.0;
    const double sf = scale_rel_sigma_[i] * along;
    const double var = b * b + sf * sf + axis_sigma_.col(i).cwiseAbs2().dot(omega_sq);  // [rad²/s²]
    out.noalias() +=
        (e * e * sqrt_period_ * sqrt_period_ * var) * s.parity.col(i) * s.parity.col(i).transpose();
  }
  out.diagonal().array() += (e * s.bias_wander_sigma) * (e * s.bias_wander_sigma);
}

}  // namespace tetra::fdi::detail
