#include "mekf.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <Eigen/Cholesky>
#include <Eigen/LU>  // the 3×3 inverse

namespace tetra::fdi::detail {

namespace {
//! Calls `f` with std::integral_constant<int, n> for the common gyro counts (3..6: the kernels' loop bounds
//! known to the compiler, unrolled and vectorized), with std::integral_constant<int, 0> (sizes at run time)
//! otherwise.
template <typename F>
decltype(auto) with_gyro_count(int n, F&& f) {
  switch (n) {
    case 3:
      return f(std::integral_constant<int, 3>{});
    case 4:
      return f(std::integral_constant<int, 4>{});
    case 5:
      return f(std::integral_constant<int, 5>{});
    case 6:
      return f(std::integral_constant<int, 6>{});
    default:
      return f(std::integral_constant<int, 0>{});
  }
}

//! The state dimension 3 + 2N for a gyro count known at compile time (`kN` > 0), Eigen::Dynamic otherwise.
constexpr int state_dim(int kN) {
  return kN > 0 ? 3 + 2 * kN : Eigen::Dynamic;
}

//! The arrays of one covariance step over n gyros: P (3 + 2n square, column-major); C = −Γ·H* (3×n, a zero
//! column for a gyro outside the solution); κ (n); D on the Gauss–Markov states, d (n, 1 when frozen), and
//! d_j·d_k (n×n); scratch for R (3 + 2n rows of n) and X (3 + 2n rows of 3).
struct CovarianceStep {
  double* P;
  const double* coupling;
  const double* kappa;
  const double* decay;
  const double* decay2;
  double* fold;
  double* cross;
};

//! P ← Φ·P·Φᵀ + Qθ with Φ = [[A, G], [0, D]] over n gyros (`kN` > 0: n known at compile time) and
//! G = [C, C·diag(κ)] factored: G·Pβ: = C·R, R = Pc: + diag(κ)·Pg: (each gyro's two bias rows folded first).
//!   X = A·Pθ: + C·R                      (3 rows: V = X(:, θ), U = X(:, β))
//!   Pθθ ← V·Aᵀ + (Uc + Ug·diag(κ))·Cᵀ + Qθ, symmetrized;   Pθβ ← U·D;   Pββ ← D·Pββ·D
//! R and X are formed transposed, as columns of P's length; P is read by columns (it is exactly symmetric:
//! every update writes both triangles alike).
template <int kN>
void propagate_blocks(const CovarianceStep& s, int n_runtime, const Eigen::Matrix3d& A,
                      const Eigen::Matrix3d& q_theta) {
  // Columns of P's length and of n as Eigen vectors of a size known at compile time: packed arithmetic.
  constexpr int kColumn = state_dim(kN);
  constexpr int kPerGyro = kN > 0 ? kN : Eigen::Dynamic;
  using Column = Eigen::Matrix<double, kColumn, 1>;
  using PerGyro = Eigen::Matrix<double, kPerGyro, 1>;
  const int n = kN > 0 ? kN : n_runtime;
  const Eigen::Index ld = 3 + 2 * n;
  double* P = s.P;
  const double* C = s.coupling;
  const double* kappa = s.kappa;
  const auto column = [&](double* p) { return Eigen::Map<Column>(p, ld); };
  // Rᵀ (ld × n): column i = P(:, c_i) + κ_i·P(:, g_i).
  for (int i = 0; i < n; ++i)
    column(s.fold + i * ld) = column(P + (3 + i) * ld) + kappa[i] * column(P + (3 + n + i) * ld);
  // Xᵀ (ld × 3): column a = P(:, θ)·A(a, :)ᵀ + Rᵀ·C(a, :)ᵀ.
  const auto cross_column = [&](int a, auto& xa) {
    xa = column(P) * A(a, 0) + column(P + ld) * A(a, 1) + column(P + 2 * ld) * A(a, 2);
    for (int i = 0; i < n; ++i) xa += column(s.fold + i * ld) * C[3 * i + a];
  };
  for (int a = 0; a < 3; ++a) {
    if constexpr (kN > 0) {  // summed in registers, stored once
      Column xa;
      cross_column(a, xa);
      column(s.cross + a * ld) = xa;
    } else {
      auto xa = column(s.cross + a * ld);
      cross_column(a, xa);
    }
  }
  const double* X = s.cross;
  // S = Uc + Ug·diag(κ) (3×n, into R's storage), then Pθθ ← V·Aᵀ + S·Cᵀ + Qθ, symmetrized.
  double* S = s.fold;
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < n; ++i) S[a * n + i] = X[a * ld + 3 + i] + kappa[i] * X[a * ld + 3 + n + i];
  Eigen::Matrix3d Ptt;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      double v = X[a * ld] * A(b, 0) + X[a * ld + 1] * A(b, 1) + X[a * ld + 2] * A(b, 2);
      for (int i = 0; i < n; ++i) v += S[a * n + i] * C[3 * i + b];
      Ptt(a, b) = v + q_theta(a, b);
    }
  }
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) P[b * ld + a] = 0.5 * (Ptt(a, b) + Ptt(b, a));
  // Pθβ ← U·D (1 on the slow biases, d on the Gauss–Markov ones), both triangles.
  for (int j = 0; j < 2 * n; ++j) {
    const double d = j < n ? 1.0 : s.decay[j - n];
    for (int a = 0; a < 3; ++a) {
      const double v = X[a * ld + 3 + j] * d;
      P[(3 + j) * ld + a] = v;
      P[a * ld + 3 + j] = v;
    }
  }
  // Pββ ← D·Pββ·D: the slow block unchanged, the mixed ones by d, the Gauss–Markov block by d_j·d_k.
  const Eigen::Map<const PerGyro> d(s.decay, n);
  for (int k = 0; k < n; ++k) {
    Eigen::Map<PerGyro> c_rows_g(P + (3 + k) * ld + 3 + n, n);  // column c_k, rows g
    Eigen::Map<PerGyro> g_rows_c(P + (3 + n + k) * ld + 3, n);  // column g_k, rows c
    Eigen::Map<PerGyro> g_rows_g(P + (3 + n + k) * ld + 3 + n, n);
    c_rows_g.array() *= d.array();
    g_rows_c *= d[k];
    g_rows_g.array() *= Eigen::Map<const PerGyro>(s.decay2 + k * n, n).array();
  }
}

//! One scalar measurement of the biases, R = 1, h = `h[i]` on gyro i's c and g (0: not measured), over P
//! (`dim` square, column-major, n gyros; `kDim` > 0: known at compile time). With the optimal gain K = P·hᵀ/s
//! the Joseph form expands to P − (P·hᵀ)(P·hᵀ)ᵀ/s: applied as P − u·uᵀ, u = P·hᵀ/√s, so both triangles round
//! alike (u_j·u_k = u_k·u_j). Each variance is kept at or above P_kk/s, the exact result's lower bound
//! ((P·hᵀ)_k² ≤ P_kk·h·P·hᵀ for P ≥ 0), which rounding could otherwise cross. `ph` receives P·hᵀ (before the
//! update), `u` is scratch; returns s = h·P·hᵀ + 1 (not finite or ≤ 0: P unchanged).
template <int kDim>
double scalar_downdate(double* P_data, const double* h, int n_runtime, Eigen::Index dim_runtime,
                       double* ph_data, double* u_data) {
  using Matrix = Eigen::Matrix<double, kDim, kDim>;
  using Vector = Eigen::Matrix<double, kDim, 1>;
  const Eigen::Index dim = kDim > 0 ? kDim : dim_runtime;
  const int n = kDim > 0 ? (kDim - 3) / 2 : n_runtime;
  Eigen::Map<Matrix> P(P_data, dim, dim);
  const auto sum_ph = [&](auto& ph) {
    ph.setZero();
    for (int i = 0; i < n; ++i) {
      if (h[i] != 0.0) ph += h[i] * (P.col(3 + i) + P.col(3 + n + i));
    }
  };
  if constexpr (kDim > 0) {  // summed in registers, stored once
    Vector ph;
    sum_ph(ph);
    Eigen::Map<Vector>(ph_data, dim) = ph;
  } else {
    Eigen::Map<Vector> ph(ph_data, dim);
    sum_ph(ph);
  }
  const Eigen::Map<const Vector> ph(ph_data, dim);
  double s = 1.0;
  for (int i = 0; i < n; ++i) s += h[i] * (ph[3 + i] + ph[3 + n + i]);
  if (!(s > 0.0) || !std::isfinite(s)) return s;
  Eigen::Map<Vector> u(u_data, dim);
  u = ph * (1.0 / std::sqrt(s));
  const double inv_s = 1.0 / s;
  for (Eigen::Index k = 0; k < dim; ++k) {
    const double floor = P(k, k) * inv_s;
    P.col(k) -= u * u[k];
    P(k, k) = std::max(P(k, k), floor);
  }
  return s;
}

//! The Joseph update P ← (I − K·H)·P·(I − K·H)ᵀ + r·K·Kᵀ for H = [I₃ 0] (P `dim` square and T its scratch,
//! K dim×3, column-major; `kDim` > 0: known at compile time), column by column: T = (I − K·H)·P =
//! P − K·P(θ, :), then P(:, k) ← T(:, k) + (r·K − T(:, θ))·K(k, :)ᵀ; symmetrized (each pair averaged).
template <int kDim>
void joseph_reference(double* P_data, double* T_data, const double* K_data, double r,
                      Eigen::Index dim_runtime) {
  using Matrix = Eigen::Matrix<double, kDim, kDim>;
  using Gain = Eigen::Matrix<double, kDim, 3>;
  const Eigen::Index dim = kDim > 0 ? kDim : dim_runtime;
  Eigen::Map<Matrix> P(P_data, dim, dim);
  Eigen::Map<Matrix> T(T_data, dim, dim);
  const Eigen::Map<const Gain> K(K_data, dim, 3);
  for (Eigen::Index k = 0; k < dim; ++k)
    T.col(k) = P.col(k) - K.col(0) * P(0, k) - K.col(1) * P(1, k) - K.col(2) * P(2, k);
  // M = r·K − T(:, θ), kept in P's first three columns (T holds what they were).
  for (Eigen::Index a = 0; a < 3; ++a) P.col(a) = r * K.col(a) - T.col(a);
  for (Eigen::Index k = 3; k < dim; ++k)
    P.col(k) = T.col(k) + P.col(0) * K(k, 0) + P.col(1) * K(k, 1) + P.col(2) * K(k, 2);
  for (Eigen::Index k = 0; k < 3; ++k)  // the first three columns last: M is read above
    T.col(k) += P.col(0) * K(k, 0) + P.col(1) * K(k, 1) + P.col(2) * K(k, 2);
  P.leftCols(3) = T.leftCols(3);
  for (Eigen::Index k = 0; k < dim; ++k) {
    for (Eigen::Index j = k + 1; j < dim; ++j) {
      const double v = 0.5 * (P(j, k) + P(k, j));
      P(j, k) = v;
      P(k, j) = v;
    }
  }
}
}  // namespace

Eigen::Matrix3d rotation_integral(const Eigen::Vector3d& omega_rad_s, double dt_s) {
  // ∫₀^Δt exp(−W u) du = I·Δt − (1 − cos θ)/|ω|²·W + (θ − sin θ)/|ω|³·W², θ = |ω|Δt, W = [ω×];
  // W² = ω·ωᵀ − |ω|²·I.
  const double w2 = omega_rad_s.squaredNorm();
  const double w = std::sqrt(w2);
  const double th = w * dt_s;
  double a = 0.0;  // (1 − cos θ)/|ω|²
  double b = 0.0;  // (θ − sin θ)/|ω|³
  if (th < 1e-3) {
    // Series to θ⁴ (relative truncation error < 1e-13 at θ = 1e-3).
    const double dt2 = dt_s * dt_s;
    a = dt2 * (0.5 - th * th / 24.0);
    b = dt2 * dt_s * (1.0 / 6.0 - th * th / 120.0);
  } else {
    a = (1.0 - std::cos(th)) / w2;
    b = (th - std::sin(th)) / (w2 * w);
  }
  Eigen::Matrix3d gamma = (b * omega_rad_s) * omega_rad_s.transpose();
  gamma.diagonal().array() += dt_s - b * w2;
  const Eigen::Vector3d aw = a * omega_rad_s;  // −a·W off the diagonal
  gamma(0, 1) += aw.z();
  gamma(1, 0) -= aw.z();
  gamma(0, 2) -= aw.y();
  gamma(2, 0) += aw.y();
  gamma(1, 2) += aw.x();
  gamma(2, 1) -= aw.x();
  return gamma;
}

Mekf::Mekf(std::vector<GyroNoiseModel> gyros)
    : gyros_(std::move(gyros)),
      n_(static_cast<int>(gyros_.size())),
      dim_(3 + 2 * static_cast<Eigen::Index>(gyros_.size())),
      P_(Eigen::MatrixXd::Zero(dim_, dim_)),
      bias_(Eigen::VectorXd::Zero(dim_ - 3)),
      decay_(Eigen::VectorXd::Ones(n_)),
      decay2_(Eigen::MatrixXd::Ones(n_, n_)),
      bias_noise_(Eigen::VectorXd::Zero(2 * n_)),
      prior_noise_(Eigen::VectorXd::Zero(n_)),
      coupling_(Eigen::Matrix3Xd::Zero(3, n_)),
      fold_(Eigen::VectorXd::Zero(dim_ * n_)),
      cross_(Eigen::VectorXd::Zero(dim_ * 3)),
      joseph_(Eigen::MatrixXd::Zero(dim_, dim_)),
      gain_(Eigen::MatrixX3d::Zero(dim_, 3)),
      ph_(Eigen::VectorXd::Zero(dim_)),
      parity_h_(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(gyros_.size()))),
      prior_var_(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(gyros_.size()))) {
  gm_phi_.assign(gyros_.size(), 1.0);  // sized once here: computing them never allocates
  gm_kappa_.assign(gyros_.size(), 1.0);
  rrw_var_.assign(gyros_.size(), 0.0);
  gm_var_.assign(gyros_.size(), 0.0);
  added_noise_.assign(gyros_.size(), 0.0);
  added_gm_var_.assign(gyros_.size(), 0.0);
  added_rrw_var_.assign(gyros_.size(), 0.0);
  step_pinv_ = Eigen::Matrix3Xd::Zero(3, n_);
  for (const auto& g : gyros_) ramps_ |= g.ramp_rad_s2 > 0.0;
  reset(0.0);
}

void Mekf::reset(double attitude_sigma_rad) {
  P_.setZero();
  bias_.setZero();
  frozen_mask_ = 0;
  for (int i = 0; i < n_; ++i) set_prior(i);
  std::fill(added_noise_.begin(), added_noise_.end(), 0.0);
  std::fill(added_gm_var_.begin(), added_gm_var_.end(), 0.0);
  std::fill(added_rrw_var_.begin(), added_rrw_var_.end(), 0.0);
  bias_ratio_ = 1.0;
  ramp_age_s_ = ramp_taken_s_ = 0.0;
  gm_dt_s_ = -1.0;
  step_dt_s_ = -1.0;  // the step constants again from the model's noise
  P_.topLeftCorner<3, 3>().diagonal().setConstant(attitude_sigma_rad * attitude_sigma_rad);
}

void Mekf::reset_attitude(double attitude_sigma_rad) {
  P_.topRows<3>().setZero();
  P_.leftCols<3>().setZero();
  P_.topLeftCorner<3, 3>().diagonal().setConstant(attitude_sigma_rad * attitude_sigma_rad);
}

void Mekf::set_prior(int i) {
  decorrelate(i);
  const auto& g = gyros_[static_cast<std::size_t>(i)];
  P_(c_of(i), c_of(i)) = g.bias_sigma_rad_s * g.bias_sigma_rad_s;
  P_(g_of(i), g_of(i)) = g.gm_sigma_rad_s * g.gm_sigma_rad_s;  // the simulator starts it stationary
  bias_[i] = 0.0;
  bias_[n_ + i] = 0.0;
  prior_var_[i] = P_(c_of(i), c_of(i)) + P_(g_of(i), g_of(i));
}

void Mekf::decorrelate(int i) {
  for (const Eigen::Index k : {c_of(i), g_of(i)}) {
    const double keep = P_(k, k);
    P_.row(k).setZero();
    P_.col(k).setZero();
    P_(k, k) = keep;
  }
  P_(c_of(i), g_of(i)) = 0.0;
  P_(g_of(i), c_of(i)) = 0.0;
}

void Mekf::save_biases(double* state) const {
  const Eigen::Index m = 2 * n_;
  Eigen::Map<Eigen::VectorXd>(state, m) = bias_;
  Eigen::Map<Eigen::MatrixXd>(state + m, m, m) = P_.bottomRightCorner(m, m);
}

void Mekf::restore_biases(const double* state, GyroMask gyros, double elapsed_s) {
  // The saved bias states propagated over `elapsed_s` with no measurement since: c a random walk, g a
  // Gauss–Markov process (decay d = e^{−t/T_c}), i.e. the block D·B·D + Q; the attitude is not in it.
  const Eigen::Index m = 2 * n_;
  const Eigen::Map<const Eigen::MatrixXd> block(state + m, m, m);
  auto restored = [&](int i) { return has_gyro(gyros, i + 1) && !frozen(i + 1); };
  auto decay = [&](Eigen::Index k) {  // k: 0..2N−1, c then g
    if (k < n_) return 1.0;
    const auto j = static_cast<std::size_t>(k - n_);
    return gm_stationary_var(j) > 0.0 ? std::exp(-elapsed_s / gyros_[j].gm_correlation_s) : 1.0;
  };
  for (int i = 0; i < n_; ++i) {  // every restored state loses its correlations first
    if (!restored(i)) continue;
    for (const Eigen::Index k : {c_of(i), g_of(i)}) {
      P_.row(k).setZero();
      P_.col(k).setZero();
    }
  }
  for (Eigen::Index a = 0; a < m; ++a) {
    if (!restored(static_cast<int>(a % n_))) continue;
    bias_[a] = state[a] * decay(a);
    for (Eigen::Index b = 0; b < m; ++b) {
      if (restored(static_cast<int>(b % n_))) P_(3 + a, 3 + b) = decay(a) * block(a, b) * decay(b);
    }
  }
  for (int i = 0; i < n_; ++i) {
    if (!restored(i)) continue;
    P_(c_of(i), c_of(i)) += walk_var_rate(static_cast<std::size_t>(i)) * elapsed_s;
    const double d = decay(n_ + i);
    P_(g_of(i), g_of(i)) += gm_stationary_var(static_cast<std::size_t>(i)) * (1.0 - d * d);
  }
}

void Mekf::restore_prior(GyroMask gyros) {
  for (int i = 0; i < n_; ++i) {
    if (has_gyro(gyros, i + 1) && !frozen(i + 1)) set_prior(i);
  }
}

void Mekf::freeze(int id) {
  if (id < 1 || id > n_) return;
  decorrelate(id - 1);
  frozen_mask_ |= GyroMask{1} << static_cast<unsigned>(id - 1);
}

void Mekf::thaw(int id) {
  if (id < 1 || id > n_) return;
  frozen_mask_ = without_gyro(frozen_mask_, id);
  set_prior(id - 1);
  set_added_noise(id, 0.0);
  clear_bias_model(id);
}

void Mekf::clear_bias_model(int id) {
  if (id < 1 || id > n_) return;
  const auto k = static_cast<std::size_t>(id - 1);
  if (added_gm_var_[k] == 0.0 && added_rrw_var_[k] == 0.0) return;
  added_gm_var_[k] = 0.0;
  added_rrw_var_[k] = 0.0;
  gm_dt_s_ = -1.0;  // the bias transitions and the step constants recomputed at the next step
  step_dt_s_ = -1.0;
}

void Mekf::open_bias_model(int id, double gm_var_rad2_s2, double rrw_var_rad2_s3) {
  if (id < 1 || id > n_ || frozen(id)) return;
  const auto k = static_cast<std::size_t>(id - 1);
  const bool gm = gm_var_rad2_s2 > added_gm_var_[k];
  const bool rrw = rrw_var_rad2_s3 > added_rrw_var_[k];
  if (!gm && !rrw) return;
  if (gm) {
    P_(g_of(id - 1), g_of(id - 1)) += gm_var_rad2_s2 - added_gm_var_[k];
    added_gm_var_[k] = gm_var_rad2_s2;
  }
  if (rrw) added_rrw_var_[k] = rrw_var_rad2_s3;
  gm_dt_s_ = -1.0;  // the bias transitions and the step constants recomputed at the next step
  step_dt_s_ = -1.0;
}

void Mekf::set_bias_model_ratio(double ratio) {
  if (!(ratio > bias_ratio_)) return;
  for (int i = 0; i < n_; ++i) {
    if (frozen(i + 1)) continue;
    const double stated = gyros_[static_cast<std::size_t>(i)].gm_sigma_rad_s;
    P_(g_of(i), g_of(i)) += (ratio - bias_ratio_) * stated * stated;
  }
  bias_ratio_ = ratio;
  gm_dt_s_ = -1.0;  // the bias transitions and the step constants recomputed at the next step
  step_dt_s_ = -1.0;
}

void Mekf::set_added_noise(int id, double added_rad2_s) {
  if (id < 1 || id > n_) return;
  double& added = added_noise_[static_cast<std::size_t>(id - 1)];
  const double v = std::max(added_rad2_s, 0.0);
  if (v == added) return;
  added = v;
  step_dt_s_ = -1.0;  // Qθ recomputed at the next step
}

Eigen::Vector3d Mekf::rate_correction(const Eigen::Matrix3Xd& pinv, GyroMask mask) const {
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (int i = 0; i < n_; ++i) {
    if (has_gyro(mask, i + 1)) w += pinv.col(i) * (bias_[i] + bias_[n_ + i]);
  }
  return w;
}

void Mekf::propagate(const Eigen::Matrix3Xd& pinv, GyroMask mask, const Eigen::Vector3d& omega_B_rad_s,
                     double dt_s) {
  if (!(dt_s > 0.0)) return;
  propagate(quat_exp(omega_B_rad_s * dt_s), pinv, mask, omega_B_rad_s, dt_s);
}

void Mekf::propagate(const Quaternion& rotation, const Eigen::Matrix3Xd& pinv, GyroMask mask,
                     const Eigen::Vector3d& omega_B_rad_s, double dt_s) {
  if (!(dt_s > 0.0)) return;
  // Transition Φ = [[A, G], [0, D]]: A rotates the body-frame error by the step's rotation (exact),
  // G = −Γ·H*·(bias states), Γ = ∫ A(u) du; D the bias models' own transitions.
  const Eigen::Matrix3d A = rotation.toRotationMatrix().transpose();
  const Eigen::Matrix3d gamma = rotation_integral(omega_B_rad_s, dt_s);
  const GyroMask used = mask & ~frozen_mask_;
  age_ramps(dt_s);
  refresh_step_constants(pinv, used, dt_s);
  for (int i = 0; i < n_; ++i) {
    if (has_gyro(used, i + 1))
      coupling_.col(i).noalias() = -gamma * pinv.col(i);
    else
      coupling_.col(i).setZero();
  }
  propagate_covariance(A, q_theta_);
  P_.diagonal().tail(2 * n_) += bias_noise_;  // zero on a frozen gyro's states
  prior_var_ += prior_noise_;                // the model's K² only: an opened model does not widen the prior
  bias_.tail(n_).array() *= decay_.array();  // 1 on a frozen gyro
  // Symmetric by construction but for the attitude block (symmetrized above).
}

void Mekf::age_ramps(double dt_s) {
  if (!ramps_) return;
  ramp_age_s_ += dt_s;
  if (ramp_age_s_ < ramp_taken_s_) return;
  ramp_taken_s_ = 1.01 * ramp_age_s_ + 1.0;
  gm_dt_s_ = -1.0;  // the bias transitions and the step constants recomputed for the new age
  step_dt_s_ = -1.0;
}

void Mekf::refresh_step_constants(const Eigen::Matrix3Xd& pinv, GyroMask used, double dt_s) {
  if (dt_s != gm_dt_s_) gauss_markov_transitions(dt_s);
  if (dt_s == step_dt_s_ && used == step_used_ && frozen_mask_ == step_frozen_ && pinv.cols() == n_ &&
      (pinv.array() == step_pinv_.array()).all())
    return;
  q_theta_.setZero();
  for (int i = 0; i < n_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const bool frozen = has_gyro(frozen_mask_, i + 1);
    decay_[i] = frozen ? 1.0 : gm_phi_[k];
    bias_noise_[i] = frozen ? 0.0 : rrw_var_[k];
    bias_noise_[n_ + i] = frozen ? 0.0 : gm_var_[k];
    const auto& g = gyros_[k];
    prior_noise_[i] = frozen ? 0.0 : stated_walk_var_rate(k) * dt_s;
    if (has_gyro(used, i + 1))
      q_theta_ +=
          pinv.col(i) * pinv.col(i).transpose() * ((g.arw_rad_rts * g.arw_rad_rts + added_noise_[k]) * dt_s);
  }
  decay2_.noalias() = decay_ * decay_.transpose();  // d_j·d_k = d_k·d_j: the block stays exactly symmetric
  if (pinv.cols() == n_) step_pinv_ = pinv;         // sized at creation: no allocation
  step_used_ = used;
  step_frozen_ = frozen_mask_;
  step_dt_s_ = dt_s;
}

void Mekf::propagate_covariance(const Eigen::Matrix3d& A, const Eigen::Matrix3d& q_theta) {
  const CovarianceStep step{P_.data(),      coupling_.data(), gm_kappa_.data(), decay_.data(),
                            decay2_.data(), fold_.data(),     cross_.data()};
  with_gyro_count(n_, [&](auto k) { propagate_blocks<decltype(k)::value>(step, n_, A, q_theta); });
}

void Mekf::gauss_markov_transitions(double dt_s) {
  for (std::size_t i = 0; i < gyros_.size(); ++i) {
    const auto& g = gyros_[i];
    const double stationary = gm_stationary_var(i);
    gm_phi_[i] = stationary > 0.0 ? std::exp(-dt_s / g.gm_correlation_s) : 1.0;
    // The Gauss–Markov bias decays within the step: its mean over the step is κ·g, κ = T_c(1 − φ)/Δt.
    gm_kappa_[i] =
        stationary > 0.0 ? g.gm_correlation_s * -std::expm1(-dt_s / g.gm_correlation_s) / dt_s : 1.0;
    rrw_var_[i] = walk_var_rate(i) * dt_s;
    gm_var_[i] = stationary * (1.0 - gm_phi_[i] * gm_phi_[i]);
  }
  gm_dt_s_ = dt_s;
}

void Mekf::add_attitude_variance(const Eigen::Vector3d& var_rad2) {
  P_.topLeftCorner<3, 3>().diagonal() += var_rad2;
}

void Mekf::add_attitude_variance_along(const Eigen::Vector3d& d, double var_rad2) {
  P_.topLeftCorner<3, 3>().noalias() += (var_rad2 * d) * d.transpose();
}

ReferenceUpdate Mekf::update_reference(const Quaternion& q_est_RB, const Quaternion& q_ref_RB,
                                       double sigma_rad, double gate_chi2) {
  ReferenceUpdate out;
  out.innovation_rad = quat_log(q_est_RB.conjugate() * q_ref_RB);
  const double r = sigma_rad * sigma_rad;
  const Eigen::Matrix3d S = P_.topLeftCorner<3, 3>() + Eigen::Matrix3d::Identity() * r;
  const Eigen::LLT<Eigen::Matrix3d> llt(S);
  if (llt.info() != Eigen::Success) return out;
  out.chi2 = out.innovation_rad.dot(llt.solve(out.innovation_rad));
  if (!(out.chi2 <= gate_chi2)) return out;
  out.accepted = true;
  // K = P·Hᵀ·S⁻¹ with H = [I₃ 0]; no gain on a frozen gyro's states.
  const Eigen::Matrix3d S_inv = S.inverse();  // positive definite (the factorization above succeeded)
  gain_.noalias() = P_.leftCols<3>() * S_inv;
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(frozen_mask_, i + 1)) continue;
    gain_.row(c_of(i)).setZero();
    gain_.row(g_of(i)).setZero();
  }
  out.correction_rad = gain_.topRows<3>() * out.innovation_rad;
  for (Eigen::Index k = 3; k < dim_; ++k) bias_[k - 3] += gain_.row(k).dot(out.innovation_rad);
  with_gyro_count(n_, [&](auto k) {
    joseph_reference<state_dim(decltype(k)::value)>(P_.data(), joseph_.data(), gain_.data(), r, dim_);
  });
  return out;
}

Eigen::Vector3d Mekf::update_parity(const Eigen::MatrixXd& W, int d, GyroMask mask, double scale,
                                    const double* p) {
  Eigen::Vector3d correction = Eigen::Vector3d::Zero();
  const GyroMask used = mask & ~frozen_mask_;
  double* h = parity_h_.data();
  double* ph = ph_.data();
  double* u = gain_.data();  // its first column (scratch)
  for (int r = 0; r < d; ++r) {
    // h: ∂p_r/∂(c_i, g_i) = scale·W(r, i) for the gyros of the mask; R = 1.
    double predicted = 0.0;
    for (int i = 0; i < n_; ++i) {
      h[i] = has_gyro(used, i + 1) ? scale * W(r, i) : 0.0;
      predicted += h[i] * (bias_[i] + bias_[n_ + i]);
    }
    const double s = with_gyro_count(n_, [&](auto k) {
      return scalar_downdate<state_dim(decltype(k)::value)>(P_.data(), h, n_, dim_, ph, u);
    });
    if (!(s > 0.0) || !std::isfinite(s)) continue;
    const double gain_nu = (p[r] - predicted) / s;
    for (Eigen::Index k = 0; k < 3; ++k) correction[k] += ph[k] * gain_nu;
    for (Eigen::Index k = 3; k < dim_; ++k) bias_[k - 3] += ph[k] * gain_nu;
  }
  return correction;
}

double Mekf::bias_z(int id) const {
  const double spread = prior_var_[id - 1];
  return spread > 0.0 ? bias_rad_s(id) / std::sqrt(spread) : 0.0;
}

void Mekf::open_fault_hypothesis(double sigma_rad_s) {
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(frozen_mask_, i + 1)) P_(c_of(i), c_of(i)) += sigma_rad_s * sigma_rad_s;
  }
}

Eigen::Vector3d Mekf::attitude_sigma_rad() const {
  return P_.topLeftCorner<3, 3>().diagonal().cwiseMax(0.0).cwiseSqrt();
}

double Mekf::bias_sigma_rad_s(int id) const {
  const int i = id - 1;
  const double v = P_(c_of(i), c_of(i)) + P_(g_of(i), g_of(i)) + 2.0 * P_(c_of(i), g_of(i));
  return std::sqrt(std::max(v, 0.0));
}

}  // namespace tetra::fdi::detail
