// The two calibration estimators (seed eqs. 4–11 and a batch least-squares fit) and the residuals of
// any calibration on turntable data. See calibration.hpp for the equations.
#include "tetra/core/calibration.hpp"

#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "calibration_rows.hpp"
#include "tetra/core/correlated_noise.hpp"
#include "tetra/core/frames.hpp"
#include "tetra/core/units.hpp"

namespace tetra {

namespace {

using Vector4d = Eigen::Matrix<double, 4, 1>;
using Matrix4d = Eigen::Matrix<double, 4, 4>;

Eigen::Index idx(std::size_t i) {
  return static_cast<Eigen::Index>(i);
}

//! 1σ of each sequence mean (M×N) [V]: the scatter of g_i − x_i·ω_B about its own sequence mean
//! (the deterministic rate signal removed), sample standard deviation / √n. One pass.
Result<Eigen::MatrixXd> sequence_sigma_of_mean(const TurntableRows& rows, const TurntableMotion& motion,
                                               const Eigen::MatrixX3d& x) {
  const int n_gyros = rows.gyro_count();
  const auto m_count = idx(motion.sequences.size());
  // Shifted by each sequence's first residual so the sums do not lose precision.
  Eigen::MatrixXd shift(m_count, n_gyros);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(m_count, n_gyros);
  Eigen::MatrixXd sum_sq = Eigen::MatrixXd::Zero(m_count, n_gyros);
  Status read = calibration_detail::for_each_rate_row(
      rows, motion, [&](const TurntableRow& row, std::size_t j, const Eigen::Vector3d& w) {
        const auto jj = idx(j);
        if (row.index == motion.sequences[j].first_row) {
          for (int i = 0; i < n_gyros; ++i) shift(jj, i) = row.g_V[i] - x.row(i).dot(w);
        }
        for (int i = 0; i < n_gyros; ++i) {
          const double e = row.g_V[i] - x.row(i).dot(w) - shift(jj, i);
          sum(jj, i) += e;
          sum_sq(jj, i) += e * e;
        }
      });
  if (!read) return read.error();
  Eigen::MatrixXd sigma(m_count, n_gyros);
  for (Eigen::Index j = 0; j < m_count; ++j) {
    const double n = static_cast<double>(motion.sequences[static_cast<std::size_t>(j)].row_count);
    for (int i = 0; i < n_gyros; ++i) {
      const double variance = std::max(0.0, (sum_sq(j, i) - sum(j, i) * sum(j, i) / n) / (n - 1.0));
      sigma(j, i) = std::sqrt(variance / n);
    }
  }
  return sigma;
}

//! The time span of every sequence, each sample standing for ±half a sampling interval.
std::vector<TimeInterval> sequence_intervals(const TurntableMotion& motion) {
  std::vector<TimeInterval> spans;
  for (const SequenceMotion& m : motion.sequences) {
    const double first_s = m.first_time_s;
    const double last_s = m.last_time_s;
    const double half_dt_s =
        m.row_count > 1 ? 0.5 * (last_s - first_s) / static_cast<double>(m.row_count - 1) : 0.0;
    spans.push_back({first_s - half_dt_s, last_s + half_dt_s});
  }
  return spans;
}

//! Covariance [V²] (M×M) of gyro i's sequence means from its correlated noise (none without a model).
Eigen::MatrixXd correlated_sequence_covariance(const TurntableMotion& motion,
                                               const CalibrationOptions& options, int gyro_index0,
                                               double scale_V_per_dps) {
  const auto m_count = idx(motion.sequences.size());
  if (options.noise.empty()) return Eigen::MatrixXd::Zero(m_count, m_count);
  const double start_s = motion.start_time_s;
  return scale_V_per_dps * scale_V_per_dps *
         correlated_mean_covariance(sequence_intervals(motion),
                                    options.noise[static_cast<std::size_t>(gyro_index0)],
                                    options.bias_instability_correlation_s, start_s);
}

//! Fills a gyro's estimate from x = s·h and β with the 4×4 covariance of (x, β):
//! s = |x|, h = x/s; ∂s/∂x = hᵀ, ∂h/∂x = (I − h hᵀ)/s.
GyroCalibration to_gyro(int id, const Eigen::Vector3d& x, double bias_V, const Matrix4d& cov) {
  GyroCalibration g;
  g.id = id;
  g.scale_factor_V_per_dps = x.norm();
  g.axis_B = x / g.scale_factor_V_per_dps;
  g.bias_V = bias_V;
  const Eigen::Matrix3d cov_x = cov.topLeftCorner<3, 3>();
  const Eigen::Matrix3d j_h =
      (Eigen::Matrix3d::Identity() - g.axis_B * g.axis_B.transpose()) / g.scale_factor_V_per_dps;
  GyroSigma s;
  s.scale_factor_V_per_dps = std::sqrt(std::max(0.0, g.axis_B.dot(cov_x * g.axis_B)));
  s.bias_V = std::sqrt(std::max(0.0, cov(3, 3)));
  s.axis = (j_h * cov_x * j_h.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
  g.sigma = s;
  return g;
}

Result<CalibrationResult> calibrate_sixteen(const TurntableRows& rows, const TurntableMotion& motion,
                                            const CalibrationOptions& options) {
  const int n_gyros = rows.gyro_count();
  const std::size_t m_count = motion.sequences.size();
  const std::size_t pairs = m_count / 2;
  const Eigen::MatrixXd& g_mean = motion.g_mean_V;

  // Eqs. 5–7: Δḡ = Ω x with Ω rows ω̄(2k−1) − ω̄(2k) (encoder-derived, Earth rate included).
  // x = Ω# Δḡ = Ω# S ḡ =: L ḡ, with S (P×M) the pair-difference operator.
  Eigen::MatrixXd omega(idx(pairs), 3);
  Eigen::MatrixXd pair_diff = Eigen::MatrixXd::Zero(idx(pairs), idx(m_count));
  for (std::size_t p = 0; p < pairs; ++p) {
    omega.row(idx(p)) =
        (motion.sequences[2 * p].rate_B_dps() - motion.sequences[2 * p + 1].rate_B_dps()).transpose();
    pair_diff(idx(p), idx(2 * p)) = 1.0;
    pair_diff(idx(p), idx(2 * p + 1)) = -1.0;
  }
  const Eigen::Matrix3d normal = omega.transpose() * omega;
  const Eigen::MatrixXd to_x = normal.ldlt().solve(omega.transpose() * pair_diff);  // L, 3×M

  // Eq. 10/11: β = cᵀ ḡ. Body: β = mean_j(ḡ_j − x·ω̄_j). Seed eq. 11: β = mean_j ḡ_j − x·ω_e^L.
  Eigen::Vector3d subtracted_dps = Eigen::Vector3d::Zero();
  if (options.bias_model == BiasModel::kBody) {
    for (const auto& m : motion.sequences) subtracted_dps += m.rate_B_dps();
    subtracted_dps /= static_cast<double>(m_count);
  } else {
    subtracted_dps = earth_rate_L(motion.latitude_deg * kDegToRad) * kRadToDeg;
  }
  const Eigen::VectorXd to_bias =
      Eigen::VectorXd::Constant(idx(m_count), 1.0 / static_cast<double>(m_count)) -
      to_x.transpose() * subtracted_dps;

  Eigen::MatrixX3d x(n_gyros, 3);
  Eigen::VectorXd bias(n_gyros);
  for (int i = 0; i < n_gyros; ++i) {
    x.row(i) = (to_x * g_mean.col(i)).transpose();
    bias(i) = to_bias.dot(g_mean.col(i));
  }
  auto sigma_of_mean = sequence_sigma_of_mean(rows, motion, x);
  if (!sigma_of_mean) return sigma_of_mean.error();
  const Eigen::MatrixXd& sigma_mean = *sigma_of_mean;

  // Linear propagation: (x, β) = [L; cᵀ] ḡ_i with cov(ḡ_i) = diag(σ_mean²).
  Eigen::MatrixXd to_params(4, idx(m_count));
  to_params.topRows(3) = to_x;
  to_params.row(3) = to_bias.transpose();
  CalibrationResult result;
  result.calibration.unit = options.unit;
  result.calibration.latitude_deg = motion.latitude_deg;
  result.calibration.method =
      options.bias_model == BiasModel::kBody ? "sixteen-position" : "sixteen-position-seed-bias";
  for (int i = 0; i < n_gyros; ++i) {
    Eigen::MatrixXd mean_cov = correlated_sequence_covariance(motion, options, i, x.row(i).norm());
    mean_cov.diagonal() += sigma_mean.col(i).array().square().matrix();
    const Matrix4d cov = to_params * mean_cov * to_params.transpose();
    result.calibration.gyros.push_back(to_gyro(i + 1, x.row(i).transpose(), bias(i), cov));
  }
  result.sequence_sigma_mean_V = sigma_mean;
  return result;
}

// The normal equations of g_i = x_i·ω_B + β_i over every sample (regressor a = (ω_B, 1), the same for
// every gyro: one normal matrix, N right-hand sides), the lower triangle of the matrix filled. One pass.
Status accumulate_normal_equations(const TurntableRows& rows, const TurntableMotion& motion, Matrix4d& normal,
                                   Eigen::Matrix<double, 4, Eigen::Dynamic>& rhs) {
  const int n_gyros = rows.gyro_count();
  normal.setZero();
  rhs = Eigen::Matrix<double, 4, Eigen::Dynamic>::Zero(4, n_gyros);
  return calibration_detail::for_each_rate_row(
      rows, motion, [&](const TurntableRow& row, std::size_t, const Eigen::Vector3d& w) {
        const Vector4d a(w.x(), w.y(), w.z(), 1.0);
        normal.selfadjointView<Eigen::Lower>().rankUpdate(a);
        for (int i = 0; i < n_gyros; ++i) rhs.col(i) += a * row.g_V[i];
      });
}

// Residual sum of squares of every gyro about the fit θ (columns (x_i, β_i)). One pass.
Result<Eigen::VectorXd> residual_sum_of_squares(const TurntableRows& rows, const TurntableMotion& motion,
                                                const Eigen::Matrix<double, 4, Eigen::Dynamic>& theta) {
  const int n_gyros = rows.gyro_count();
  Eigen::VectorXd rss = Eigen::VectorXd::Zero(n_gyros);
  Status read = calibration_detail::for_each_rate_row(
      rows, motion, [&](const TurntableRow& row, std::size_t, const Eigen::Vector3d& w) {
        for (int i = 0; i < n_gyros; ++i) {
          const double e = row.g_V[i] - theta.col(i).head<3>().dot(w) - theta(3, i);
          rss(i) += e * e;
        }
      });
  if (!read) return read.error();
  return rss;
}

Result<CalibrationResult> calibrate_batch(const TurntableRows& rows, const TurntableMotion& motion,
                                          const CalibrationOptions& options) {
  const int n_gyros = rows.gyro_count();
  Matrix4d normal;
  Eigen::Matrix<double, 4, Eigen::Dynamic> rhs;
  if (Status s = accumulate_normal_equations(rows, motion, normal, rhs); !s) return s.error();
  normal = normal.selfadjointView<Eigen::Lower>();
  const Eigen::LDLT<Matrix4d> ldlt(normal);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) {
    return bad_input(rows.source() +
                     ": the batch fit is singular: the samples do not separate rates and biases");
  }
  const Eigen::Matrix<double, 4, Eigen::Dynamic> theta = ldlt.solve(rhs);
  const Matrix4d normal_inv = ldlt.solve(Matrix4d::Identity());
  auto rss_of = residual_sum_of_squares(rows, motion, theta);
  if (!rss_of) return rss_of.error();
  const Eigen::VectorXd& rss = *rss_of;
  const double dof = static_cast<double>(rows.rows()) - 4.0;
  if (dof < 1.0) return bad_input(rows.source() + ": too few rows for the batch fit");

  CalibrationResult result;
  result.calibration.unit = options.unit;
  result.calibration.latitude_deg = motion.latitude_deg;
  result.calibration.method = "batch";
  // Correlated noise: nearly constant regressor within a sequence, so Aᵀ Σ A ≈ Āᵀ C Ā with Ā's rows
  // n_j·(mean regressor of sequence j) and C the covariance of the sequence means.
  Eigen::MatrixXd summed_regressor(idx(motion.sequences.size()), 4);
  for (std::size_t j = 0; j < motion.sequences.size(); ++j) {
    const SequenceMotion& m = motion.sequences[j];
    const Eigen::Vector3d w_sum = m.rate_B_dps() * static_cast<double>(m.row_count);
    summed_regressor.row(idx(j)) << w_sum.transpose(), static_cast<double>(m.row_count);
  }
  Eigen::MatrixX3d x(n_gyros, 3);
  for (int i = 0; i < n_gyros; ++i) {
    x.row(i) = theta.col(i).head<3>().transpose();
    const Eigen::MatrixXd mean_cov =
        correlated_sequence_covariance(motion, options, i, theta.col(i).head<3>().norm());
    const Matrix4d correlated = summed_regressor.transpose() * mean_cov * summed_regressor;
    const Matrix4d cov = (rss(i) / dof) * normal_inv + normal_inv * correlated * normal_inv;
    result.calibration.gyros.push_back(to_gyro(i + 1, theta.col(i).head<3>(), theta(3, i), cov));
  }
  auto sigma_mean = sequence_sigma_of_mean(rows, motion, x);
  if (!sigma_mean) return sigma_mean.error();
  result.sequence_sigma_mean_V = std::move(sigma_mean.value());
  return result;
}

}  // namespace

Result<CalibrationFit> evaluate_calibration(const TurntableRows& rows, const TurntableMotion& motion,
                                            const Calibration& calibration) {
  const int n_gyros = rows.gyro_count();
  if (calibration.gyro_count() != n_gyros) {
    return bad_input("the calibration has " + std::to_string(calibration.gyro_count()) + " gyros, " +
                     rows.source() + " has " + std::to_string(n_gyros));
  }
  if (motion.rows != rows.rows()) return failure("evaluate_calibration: motion does not match the log");
  const Eigen::MatrixX3d axes = calibration.axes_B();
  Eigen::MatrixX3d x(n_gyros, 3);
  Eigen::VectorXd bias(n_gyros);
  for (int i = 0; i < n_gyros; ++i) {
    x.row(i) = calibration.gyros[static_cast<std::size_t>(i)].scale_factor_V_per_dps * axes.row(i);
    bias(i) = calibration.gyros[static_cast<std::size_t>(i)].bias_V;
  }
  CalibrationFit fit;
  const auto m_count = idx(motion.sequences.size());
  fit.sequence_residual_V = Eigen::MatrixXd::Zero(m_count, n_gyros);
  Eigen::VectorXd sum_sq = Eigen::VectorXd::Zero(n_gyros);
  Status read = calibration_detail::for_each_rate_row(
      rows, motion, [&](const TurntableRow& row, std::size_t j, const Eigen::Vector3d& w) {
        for (int i = 0; i < n_gyros; ++i) {
          const double e = row.g_V[i] - x.row(i).dot(w) - bias(i);
          fit.sequence_residual_V(idx(j), i) += e;
          sum_sq(i) += e * e;
        }
      });
  if (!read) return read.error();
  std::size_t samples = 0;
  for (std::size_t j = 0; j < motion.sequences.size(); ++j) {
    fit.sequence_residual_V.row(idx(j)) /= static_cast<double>(motion.sequences[j].row_count);
    samples += motion.sequences[j].row_count;
  }
  fit.sample_rms_V = (sum_sq / static_cast<double>(samples)).cwiseSqrt();
  fit.sequence_rms_V = (fit.sequence_residual_V.colwise().squaredNorm() / static_cast<double>(m_count))
                           .transpose()
                           .cwiseSqrt();
  return fit;
}

Result<CalibrationFit> evaluate_calibration(const TurntableLog& log, const TurntableMotion& motion,
                                            const Calibration& calibration) {
  return evaluate_calibration(TurntableLogRows(log), motion, calibration);
}

Result<CalibrationResult> calibrate(const TurntableRows& rows, const TurntableMotion& motion,
                                    const CalibrationOptions& options) {
  if (motion.rows != rows.rows() || motion.sequences.empty()) {
    return failure("calibrate: the motion was not derived from this log");
  }
  if (!options.noise.empty() && options.noise.size() != static_cast<std::size_t>(rows.gyro_count())) {
    return bad_input("the noise model has " + std::to_string(options.noise.size()) + " gyros, " +
                     rows.source() + " has " + std::to_string(rows.gyro_count()));
  }
  if (!(options.bias_instability_correlation_s > 0.0)) {
    return bad_input("the bias-instability correlation time must be positive");
  }
  auto result = options.method == CalibrationMethod::kSixteen ? calibrate_sixteen(rows, motion, options)
                                                              : calibrate_batch(rows, motion, options);
  if (!result) return result;
  for (const auto& g : result->calibration.gyros) {
    if (!std::isfinite(g.scale_factor_V_per_dps) || g.scale_factor_V_per_dps <= 0.0 ||
        !std::isfinite(g.bias_V)) {
      return bad_input(rows.source() + ": gyro " + std::to_string(g.id) +
                       " has no usable estimate (its output does not follow the table rates)");
    }
  }
  auto fit = evaluate_calibration(rows, motion, result->calibration);
  if (!fit) return fit.error();
  result->fit = std::move(fit.value());
  return result;
}

Result<CalibrationResult> calibrate(const TurntableLog& log, const TurntableMotion& motion,
                                    const CalibrationOptions& options) {
  return calibrate(TurntableLogRows(log), motion, options);
}

}  // namespace tetra
