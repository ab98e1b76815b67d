#pragma once
// The N-gyro multiplicative extended Kalman filter (docs/fdi.md, "Attitude filter"): the covariance of the
// attitude error and of every gyro's bias, propagated exactly for the step and updated by attitude reference
// samples (Joseph form, 3-dof χ² gate).
//
// State (3 + 2N), errors of the estimate:
//   δθ      [rad]   attitude error in B: q_true = q̂ ⊗ exp(δθ)
//   c_i     [rad/s] gyro i's slow bias: the calibration residual (1σ of the calibration) plus the rate random
//                   walk K (a random walk: c_{k+1} = c_k + K·√Δt·n)
//   g_i     [rad/s] gyro i's bias instability B: first-order Gauss–Markov, correlation time T_c,
//                   stationary σ = 1.0760·B (the process whose Allan peak is IEEE 952's 0.664·B floor)
// The gyro reads y_i = h_i·ω + c_i + g_i + n_i (n_i white, N_i); the rate is ω̂ = H*(y − ĉ − ĝ).
//
// The attitude itself (the quaternion) is the caller's: the filter returns the correction to apply.
// Storage is sized once at creation; no step allocates.

#include <vector>

#include <Eigen/Core>

#include "tetra/core/geometry.hpp"
#include "tetra/core/quaternion.hpp"

namespace tetra::fdi::detail {

//! One gyro's noise as the filter models it.
struct GyroNoiseModel {
  double arw_rad_rts = 0.0;         //!< [rad/√s] white rate noise N
  double bias_sigma_rad_s = 0.0;    //!< [rad/s] 1σ of the calibrated bias (initial σ of c_i)
  double rrw_rad_s_rts = 0.0;       //!< [rad/s/√s] rate random walk K (drives c_i)
  double gm_sigma_rad_s = 0.0;      //!< [rad/s] stationary σ of g_i (1.0760·B)
  double gm_correlation_s = 100.0;  //!< [s] T_c of g_i
  //! [rad/s²] |R|, the stated rate ramp: c_i's variance grows by 2R²·t per second, t the time since the
  //! reset, so its 1σ is R·t (a bias that wanders without bound, not a margin over a horizon)
  double ramp_rad_s2 = 0.0;
};

//! The outcome of one reference sample.
struct ReferenceUpdate {
  bool accepted = false;
  double chi2 = 0.0;                                         //!< zᵀS⁻¹z of the innovation (3 dof)
  Eigen::Vector3d innovation_rad = Eigen::Vector3d::Zero();  //!< z = log(q̂* ⊗ q_ref)
  Eigen::Vector3d correction_rad = Eigen::Vector3d::Zero();  //!< δθ̂: apply q̂ ← q̂ ⊗ exp(δθ̂)
};

class Mekf {
 public:
  explicit Mekf(std::vector<GyroNoiseModel> gyros);

  //! Initial covariance: attitude σ [rad] per axis, biases at their prior; estimates zero; nothing frozen.
  void reset(double attitude_sigma_rad);
  //! A new attitude known to σ [rad] per axis (e.g. from a reference sample); biases keep their estimates,
  //! their correlation with the attitude is dropped.
  void reset_attitude(double attitude_sigma_rad);

  //! The bias correction of the rate: H*(ĉ + ĝ) over the gyros of `mask` [rad/s].
  Eigen::Vector3d rate_correction(const Eigen::Matrix3Xd& pinv, GyroMask mask) const;

  //! One step of length `dt_s` with the rate `omega_B_rad_s` (the body's inertial rate as propagated) and the
  //! rate solution `pinv` over the gyros of `mask`: Φ exact for the rotation, biases exact for their models.
  void propagate(const Eigen::Matrix3Xd& pinv, GyroMask mask, const Eigen::Vector3d& omega_B_rad_s,
                 double dt_s);
  //! The same with the step's body rotation exp(½·ω·Δt) already at hand (`rotation`, from the propagator).
  void propagate(const Quaternion& rotation, const Eigen::Matrix3Xd& pinv, GyroMask mask,
                 const Eigen::Vector3d& omega_B_rad_s, double dt_s);

  //! Adds a variance [rad²] per axis to the attitude (e.g. a bound turned into a 1σ before an update).
  void add_attitude_variance(const Eigen::Vector3d& var_rad2);
  //! Adds `var_rad2` [rad²] along the unit body direction `d` to the attitude: P_θθ += var·d·dᵀ.
  void add_attitude_variance_along(const Eigen::Vector3d& d, double var_rad2);

  //! Gyro `id`'s white rate noise as the filter models it from the next step on: N_i² + `added_rad2_s`
  //! [rad²/s] (≥ 0; the noise the reference's innovations show beyond the model, docs/fdi.md "Reference
  //! consistency"). reset() and thaw() put it back to the model's.
  void set_added_noise(int id, double added_rad2_s);
  //! Gyro `id`'s bias as the filter models it from now on: g_i a Gauss–Markov process of stationary variance
  //! σ_GM² + `gm_var_rad2_s2` [rad²/s²] (same T_c), c_i a random walk of K² + `rrw_var_rad2_s3` [rad²/s³] — a
  //! slow rate error the parity shows beyond the bias model (docs/fdi.md, "A slow error below the
  //! detectors"). Each added variance only grows: a larger Gauss–Markov one opens g_i's variance by the
  //! difference at once. reset() and thaw() put the model back.
  void open_bias_model(int id, double gm_var_rad2_s2, double rrw_var_rad2_s3);
  //! Gyro `id`'s bias back to the model's processes (its current variance kept).
  void clear_bias_model(int id);
  //! Every gyro's bias terms as stated (σ_GM², K², the ramp's 2R²·t) taken as `ratio` times the
  //! calibration's from the next step on (≥ 1, only grows): the data showed the unit's white noise that many
  //! times its stated variance, so its `noise:` does not describe it, and its bias terms, which take far
  //! longer to measure, are taken no better than its white noise (docs/fdi.md, "A unit noisier than its
  //! `noise:` section"). The Gauss–Markov variances open by the difference at once. reset() puts 1 back.
  void set_bias_model_ratio(double ratio);
  //! [rad²/s²] gyro `id`'s variance added to its Gauss–Markov bias (open_bias_model), 0 by default.
  double added_bias_instability(int id) const { return added_gm_var_[static_cast<std::size_t>(id - 1)]; }
  //! [rad²/s³] gyro `id`'s variance rate added to its random-walk bias (open_bias_model), 0 by default.
  double added_rate_random_walk(int id) const { return added_rrw_var_[static_cast<std::size_t>(id - 1)]; }
  //! [rad/√s] gyro `id`'s modelled white rate noise N (without any added noise).
  double arw_rad_rts(int id) const { return gyros_[static_cast<std::size_t>(id - 1)].arw_rad_rts; }

  //! A reference sample of the attitude, 1σ `sigma_rad` per axis; rejected (nothing changed) when the χ² of
  //! its innovation exceeds `gate_chi2`. An accepted sample updates the biases itself; the caller applies
  //! `correction_rad` to its quaternion.
  ReferenceUpdate update_reference(const Quaternion& q_est_RB, const Quaternion& q_ref_RB, double sigma_rad,
                                   double gate_chi2);

  //! The epoch's normalized parity `p` (d rows, p = scale·W·y ~ N(0, I) without fault; W d×N over the gyros
  //! of `mask`) as a measurement of the biases: with the reference it makes each gyro's bias observable.
  //! Sequential scalar updates (the Joseph form with the optimal gain, expanded: P − P·hᵀ·h·P/s); returns the
  //! attitude correction δθ̂ to apply (q̂ ← q̂ ⊗ exp(δθ̂)).
  Eigen::Vector3d update_parity(const Eigen::MatrixXd& W, int d, GyroMask mask, double scale,
                                const double* p);

  //! A fault of unknown gyro and size up to ~`sigma_rad_s` has appeared: every active gyro's slow bias state
  //! gains that variance, so the measurements can put the step where it belongs.
  void open_fault_hypothesis(double sigma_rad_s);

  //! Gyro `id`'s bias estimate over its fault-free spread (the prior σ of c + g, which bounds the estimate's
  //! own spread): |z| ≤ N(0, 1) in distribution while the model holds; a fault on the gyro drives it away.
  double bias_z(int id) const;

  //! The bias states (2N: c then g) and their covariance block (2N × 2N), into `state` (2N + 4N² values).
  void save_biases(double* state) const;
  //! The bias states of the unfrozen gyros of `gyros` back to `state` (a `save_biases` of `elapsed_s` ago):
  //! estimates and their block of the covariance as saved, plus the process noise of `elapsed_s` (K²·t on c,
  //! σ_GM²(1 − e^{−2t/T_c}) on g); their correlation with the attitude and the other states dropped.
  void restore_biases(const double* state, GyroMask gyros, double elapsed_s);
  //! The unfrozen gyros of `gyros` back at their prior (nothing saved to restore).
  void restore_prior(GyroMask gyros);
  //! Values `save_biases` writes.
  Eigen::Index saved_size() const { return 2 * n_ + 4 * n_ * n_; }

  //! Gyro `id` (1..N) leaves the solution: its bias states keep their estimate and variance, uncorrelated
  //! with the rest, and stop evolving. `thaw` puts them back at their prior.
  void freeze(int id);
  void thaw(int id);
  bool frozen(int id) const { return has_gyro(frozen_mask_, id); }

  //! [rad] 1σ of the attitude error per body axis.
  Eigen::Vector3d attitude_sigma_rad() const;
  //! [rad/s] gyro `id`'s bias estimate (c + g) and its 1σ.
  double bias_rad_s(int id) const { return bias_[id - 1] + bias_[n_ + id - 1]; }
  double bias_sigma_rad_s(int id) const;
  int gyro_count() const { return n_; }
  //! Gyro `id`'s noise as the filter models it (the calibration's, without anything added).
  const GyroNoiseModel& noise_model(int id) const { return gyros_[static_cast<std::size_t>(id - 1)]; }
  //! The covariance (3 + 2N square: δθ, then c_1..c_N, then g_1..g_N).
  const Eigen::MatrixXd& covariance() const { return P_; }

 private:
  Eigen::Index c_of(int i) const { return 3 + i; }       //!< state index of c_i (i 0-based)
  Eigen::Index g_of(int i) const { return 3 + n_ + i; }  //!< state index of g_i
  void decorrelate(int i);
  void set_prior(int i);
  void gauss_markov_transitions(double dt_s);
  void refresh_step_constants(const Eigen::Matrix3Xd& pinv, GyroMask used, double dt_s);
  //! The stated ramps one step older: the step's constants recomputed when their age is passed.
  void age_ramps(double dt_s);
  void propagate_covariance(const Eigen::Matrix3d& A, const Eigen::Matrix3d& q_theta);
  //! [rad²/s²] gyro index `i`'s Gauss–Markov stationary variance: the model's σ_GM² and any added.
  double gm_stationary_var(std::size_t i) const {
    return bias_ratio_ * (gyros_[i].gm_sigma_rad_s * gyros_[i].gm_sigma_rad_s) + added_gm_var_[i];
  }

  std::vector<GyroNoiseModel> gyros_;
  int n_;
  Eigen::Index dim_;      //!< 3 + 2N
  Eigen::MatrixXd P_;     //!< covariance
  Eigen::VectorXd bias_;  //!< [rad/s] ĉ (0..N−1) then ĝ (N..2N−1)
  //! Per gyro, the Gauss–Markov transition φ = e^(−Δt/T_c) and step mean κ = T_c(1 − φ)/Δt, computed for
  //! `gm_dt_s_` only (the step is nearly always the same: no exp per gyro per step).
  std::vector<double> gm_phi_;
  std::vector<double> gm_kappa_;
  std::vector<double> rrw_var_;  //!< [rad²/s²] per gyro: K²·Δt, the slow bias's variance gain over a step
  std::vector<double> gm_var_;  //!< [rad²/s²] per gyro: σ_GM²(1 − φ²), the Gauss–Markov's over a step
  double gm_dt_s_ = -1.0;
  //! [s] the time since the reset (the stated ramps' age), and the age the step's constants take for it: at
  //! least the true age (recomputed when it is passed, then 1 % + 1 s ahead); only with a stated ramp
  double ramp_age_s_ = 0.0;
  double ramp_taken_s_ = 0.0;
  bool ramps_ = false;
  //! [rad²/s³] gyro i's slow bias variance rate as stated: K² and the stated ramp's 2R²·t
  double stated_walk_var_rate(std::size_t i) const {
    const double r = gyros_[i].ramp_rad_s2;
    return bias_ratio_ * (gyros_[i].rrw_rad_s_rts * gyros_[i].rrw_rad_s_rts + 2.0 * r * r * ramp_taken_s_);
  }
  //! [rad²/s³] the same with an opened model's addition
  double walk_var_rate(std::size_t i) const { return stated_walk_var_rate(i) + added_rrw_var_[i]; }
  //! What a step keeps while the gyro set, the frozen set, the rate solution and Δt stay the same (nearly
  //! always), recomputed when the key (`step_pinv_`, `step_used_`, `step_frozen_`, `step_dt_s_`) changes:
  //! the attitude's process noise Qθ = H*·diag(N²)·H*ᵀ·Δt; D on the Gauss–Markov states, d per gyro
  //! (`decay_`, 1 when frozen) and d_j·d_k (`decay2_`, N×N); the bias states' variance gain over the step
  //! (`bias_noise_` [rad²/s²], c then g, 0 when frozen).
  Eigen::VectorXd decay_;
  Eigen::MatrixXd decay2_;
  Eigen::VectorXd bias_noise_;
  Eigen::VectorXd prior_noise_;  //!< [rad²/s²] per gyro: the model's K²·Δt over a step (0 when frozen)
  Eigen::Matrix3d q_theta_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3Xd step_pinv_;
  GyroMask step_used_ = 0;
  GyroMask step_frozen_ = 0;
  double step_dt_s_ = -1.0;
  GyroMask frozen_mask_ = 0;  //!< the frozen gyros (bit i − 1: gyro i)
  Eigen::Matrix3Xd coupling_;  //!< 3×N: C = −Γ·H*, ∂δθ/∂c_i over the step (on g_i: κ_i·C) (scratch)
  Eigen::VectorXd fold_;       //!< (3+2N)×N: Rᵀ of the propagation (scratch)
  Eigen::VectorXd cross_;      //!< (3+2N)×3: Xᵀ of the propagation (scratch)
  Eigen::MatrixXd joseph_;     //!< (3+2N)² scratch of the Joseph update
  Eigen::MatrixX3d gain_;      //!< (3+2N)×3 Kalman gain
  Eigen::VectorXd ph_;         //!< (3+2N) P·hᵀ of a scalar update (scratch)
  Eigen::VectorXd parity_h_;          //!< N: a parity row's h per gyro (scratch)
  Eigen::VectorXd prior_var_;         //!< [rad²/s²] per gyro: the variance of c + g without any measurement
  std::vector<double> added_noise_;   //!< [rad²/s] per gyro: white rate noise added to N² (set_added_noise)
  std::vector<double> added_gm_var_;  //!< [rad²/s²] per gyro: added to σ_GM² (open_bias_model)
  std::vector<double> added_rrw_var_;  //!< [rad²/s³] per gyro: added to K² (open_bias_model)
  double bias_ratio_ = 1.0;            //!< [-] the stated bias terms' factor (set_bias_model_ratio)
};

//! ∫₀^Δt exp(−[ω×]u) du in closed form (a series for small |ω|Δt).
Eigen::Matrix3d rotation_integral(const Eigen::Vector3d& omega_rad_s, double dt_s);

}  // namespace tetra::fdi::detail
