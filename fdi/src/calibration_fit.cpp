#include "calibration_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {

namespace {
//! Eigenvalues of S below this share of the largest carry no information (a rate never varied about them).
constexpr double kRankTolerance = 1e-12;
}  // namespace

void CalibrationFit::reset() {
  mask_ = 0;
  dof_ = 0;
  streak_ = 0;
  mismatch_ = false;
  seen_nominal_ = false;
  rows_.clear();
}

void CalibrationFit::restart(const Subset& s, GyroMask mask, const Eigen::Vector3d& omega_rad_s,
                             std::int64_t now_ns) {
  if (mask != mask_ || s.dof != dof_) {
    mask_ = mask;
    dof_ = s.dof;
    const Eigen::Index d = dof_;
    sum_wp_.resize(3, d);
    sum_p_.resize(d);
    z_.resize(3 * d);
    whitened_z_.resize(3 * d);
    cov_.resize(3 * d, 3 * d);
    tolerance_.resize(3 * d, 3 * d);
    basis_.resize(3 * d, 3);
    whitened_basis_.resize(3 * d, 3);
    solver_ = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(3 * d);
  }
  start_ns_ = now_ns;
  epochs_ = 0.0;
  sum_ww_.setZero();
  sum_w_.setZero();
  sum_dev_.setZero();
  first_w_ = omega_rad_s;
  sum_wp_.setZero();
  sum_p_.setZero();
  sum_pp_ = 0.0;
}

void CalibrationFit::accumulate(const Eigen::VectorXd& p, int dof, const Eigen::Vector3d& omega_rad_s) {
  epochs_ += 1.0;
  sum_ww_.noalias() += omega_rad_s * omega_rad_s.transpose();
  sum_w_ += omega_rad_s;
  sum_dev_ += (omega_rad_s - first_w_).cwiseAbs();
  for (int j = 0; j < dof; ++j) sum_wp_.col(j) += omega_rad_s * p[j];
  sum_p_ += p.head(dof);
  sum_pp_ += p.head(dof).squaredNorm();
}

bool CalibrationFit::record(const Eigen::VectorXd& p, const Subset& s, GyroMask mask,
                            const Eigen::Vector3d& omega_rad_s, std::int64_t now_ns, const SubsetCache& cache,
                            const PipelineConfig& config) {
  if (s.dof < 1 || !s.observable) return false;
  if (mask != mask_ || s.dof != dof_) {  // a new gyro set: judged anew
    streak_ = 0;
    mismatch_ = false;
    restart(s, mask, omega_rad_s, now_ns);
  } else if (restart_pending_) {
    restart(s, mask, omega_rad_s, now_ns);
  }
  restart_pending_ = false;
  accumulate(p, s.dof, omega_rad_s);
  if (now_ns - start_ns_ < seconds_to_ns(design::motion_fit_block_s)) return false;
  const bool named = judge_block(s, mask, cache, config);
  restart(s, mask, omega_rad_s, now_ns);
  streak_ = named ? streak_ + 1 : 0;
  if (streak_ < design::motion_fit_blocks_in_a_row || mismatch_) return false;
  mismatch_ = true;
  return true;
}

void CalibrationFit::moments(const Subset& s, GyroMask mask, const SubsetCache& cache,
                             const PipelineConfig& config) {
  const double n = epochs_;
  const Eigen::Vector3d mean_w = sum_w_ / n;
  omega_c_ = sum_ww_ - n * mean_w * mean_w.transpose();
  for (int j = 0; j < dof_; ++j) z_.segment<3>(3 * j) = sum_wp_.col(j) - mean_w * sum_p_[j];
  // Under H0, z = Σ (ω − ω̄)·n_kᵀ: Ω_c per parity axis (the noise is white, unit, independent of the rate
  // estimate's); the calibration within its tolerance adds Ω_c·C·Ω_c; a bias that wanders by δ within the
  // block adds at most δ·Σ|ω − ω_first| per axis (a constant bias cancels in the centred sums).
  cache.rate_coefficient_covariance(s, mask, tolerance_);
  const double wander = std::max(config.calibration_error_sigmas, 1.0) * s.bias_wander_sigma;
  const Eigen::Matrix3d own = noise_scale() * omega_c_ + wander * wander * sum_dev_ * sum_dev_.transpose();
  for (int j = 0; j < dof_; ++j) {
    for (int k = 0; k < dof_; ++k) {
      cov_.block<3, 3>(3 * j, 3 * k).noalias() = omega_c_ * tolerance_.block<3, 3>(3 * j, 3 * k) * omega_c_;
      if (j == k) cov_.block<3, 3>(3 * j, 3 * k) += own;
    }
  }
}

double CalibrationFit::noise_scale() const {
  // The parity's spread about the block's fit, per axis and epoch: 1 for the stated noise. A unit noisier
  // than its noise: section widens the noise term by what the data show (never narrows it).
  const double n = epochs_;
  const double centred = sum_pp_ - sum_p_.squaredNorm() / n;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rate(omega_c_);
  const double floor = kRankTolerance * std::max(rate.eigenvalues().maxCoeff(), 0.0);
  double fitted = 0.0;
  int fitted_dof = 0;
  for (int k = 0; k < 3; ++k) {
    const double lambda = rate.eigenvalues()[k];
    if (!(lambda > floor && lambda > 0.0)) continue;
    ++fitted_dof;
    for (int j = 0; j < dof_; ++j) {
      const double along = rate.eigenvectors().col(k).dot(z_.segment<3>(3 * j));
      fitted += along * along / lambda;
    }
  }
  const double dof = static_cast<double>(dof_) * (n - 1.0 - fitted_dof);
  return dof > 0.0 ? std::max(1.0, (centred - fitted) / dof) : 1.0;
}

double CalibrationFit::residual(const Eigen::MatrixXd& basis, int columns, int& dof) {
  const auto& lambda = solver_.eigenvalues();
  const auto& u = solver_.eigenvectors();
  const double floor = kRankTolerance * std::max(lambda.maxCoeff(), 0.0);
  whitened_z_.noalias() = u.transpose() * z_;
  whitened_basis_.leftCols(columns).noalias() = u.transpose() * basis.leftCols(columns);
  dof = 0;
  double chi2 = 0.0;
  for (Eigen::Index k = 0; k < lambda.size(); ++k) {
    const double scale = lambda[k] > floor && lambda[k] > 0.0 ? 1.0 / std::sqrt(lambda[k]) : 0.0;
    whitened_z_[k] *= scale;
    whitened_basis_.row(k).head(columns) *= scale;
    if (scale > 0.0) ++dof;
    chi2 += whitened_z_[k] * whitened_z_[k];
  }
  if (columns == 0) return chi2;
  // The hypothesis's form fitted by least squares in the whitened space: its projection leaves the fit.
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
  const auto b = whitened_basis_.leftCols(columns);
  const Small g = b.transpose() * b;
  const SmallVector r = b.transpose() * whitened_z_;
  const Eigen::SelfAdjointEigenSolver<Small> small(g);
  const double small_floor = kRankTolerance * std::max(small.eigenvalues().maxCoeff(), 0.0);
  for (int k = 0; k < columns; ++k) {
    const double mu = small.eigenvalues()[k];
    if (!(mu > small_floor && mu > 0.0)) continue;
    const double along = small.eigenvectors().col(k).dot(r);
    chi2 -= along * along / mu;
    --dof;
  }
  return std::max(chi2, 0.0);
}

bool CalibrationFit::judge_block(const Subset& s, GyroMask mask, const SubsetCache& cache,
                                 const PipelineConfig& config) {
  rows_.clear();
  if (epochs_ < design::motion_fit_min_epochs) return false;
  moments(s, mask, cache, config);
  solver_.compute(cov_);
  if (solver_.info() != Eigen::Success) return false;
  const double p = allocated_probability(config, BudgetTest::kMotionFit);
  const auto threshold = [p](int dof) { return dof >= 1 ? chi2_threshold(p, dof) : kNaN; };
  int dof0 = 0;
  h0_statistic_ = residual(basis_, 0, dof0);
  h0_dof_ = dof0;
  h0_threshold_ = threshold(dof0);
  rows_.add(judge(EvidenceSource::kMotionFit, kHypothesisNone, dof0 >= 1 ? h0_statistic_ : kNaN,
                  h0_threshold_, h0_threshold_, dof0));
  // Hi: gyro i alone errs, p = √T·w_i·gᵀ·ω: with four gyros (one parity axis, which any gyro's error
  // fills) its scale factor, g ∥ h_i — the form of a stuck, zero or scale fault; from five on any g.
  const int columns = dof_ == 1 ? 1 : 3;
  for (int i = 0; i < cache.gyro_count(); ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    const Eigen::Vector3d h = cache.geometry().axes_B().row(i).transpose();
    for (int j = 0; j < dof_; ++j) {
      const double w = cache.sqrt_period() * s.parity(j, i);
      if (columns == 1) {
        basis_.block<3, 1>(3 * j, 0) = w * (omega_c_ * h);
      } else {
        basis_.block<3, 3>(3 * j, 0) = w * omega_c_;
      }
    }
    int dof = 0;
    const double r = residual(basis_, columns, dof);
    const double t = threshold(dof);
    rows_.add(
        judge(EvidenceSource::kMotionFit, static_cast<std::uint8_t>(i + 1), dof >= 1 ? r : kNaN, t, t, dof));
  }
  const bool motion = dof0 >= 1 && h0_statistic_ > h0_threshold_;
  rows_.add(stated(EvidenceSource::kMotionFit, kHypothesisCalibration,
                   motion ? RowVerdict::kConsistent : RowVerdict::kNoCall, h0_statistic_, h0_threshold_,
                   dof0));
  return fdi::arbitrate_calibration(rows_.begin(), rows_.end(), mask);
}

void CalibrationFit::add_hcal_rows(EvidenceSource evidence, const EvidenceRows* episode,
                                   EvidenceRows& rows) const {
  if (reads_own_signal(evidence)) return;
  if (mismatch_)
    rows.add(stated(EvidenceSource::kMotionFit, kHypothesisCalibration, RowVerdict::kConsistent,
                    h0_statistic_, h0_threshold_, h0_dof_));
  if (!seen_nominal_ && episode != nullptr && !episode->empty()) {
    LedgerRow since_start = *episode->begin();
    since_start.hypothesis = kHypothesisCalibration;
    since_start.verdict = RowVerdict::kConsistent;
    rows.add(since_start);
  }
}

}  // namespace tetra::fdi::detail
