#pragma once
// Everything that depends on the gyro subset only — weighted pseudoinverse, whitened parity matrix, noise per
// axis, the thresholds of the parity tests — computed once per subset, and the two kernels every stage uses
// to apply them (docs/fdi.md, "Noise model and normalized parity").

#include <cmath>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/correlated_noise.hpp"  // kGaussMarkovSigmaPerB
#include "tetra/core/geometry.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/detectors.hpp"  // CusumDesign

namespace tetra::fdi::detail {

struct Subset {
  GyroMask mask = 0;
  bool observable = false;
  int dof = 0;             //!< parity dimension |S| − 3
  Eigen::Matrix3Xd pinv;   //!< 3×N weighted pseudoinverse (zero columns outside S)
  Eigen::MatrixXd parity;  //!< d×N normalized parity in 1/(rad/s) per √s: p = √T·W·y, whitened by the
                           //!< white noise N_i (the long-run noise every averaging test sees)
  Eigen::MatrixXd sample_parity;     //!< the same whitened by the noise of one sample (N_i and quantization
                                     //!< Q_i): the instantaneous χ²; equals `parity` without quantization
  Eigen::MatrixXd jump_parity;       //!< whitened by the noise of a one-sample difference: the jump test
  Eigen::VectorXd parity_col_norm;   //!< [1/(rad/s)·√s] |w_i| = |column i of `parity`| (0 outside S)
  bool quantized = false;            //!< some gyro of the subset has an angle quantization
  double quantization_margin = 0.0;  //!< [σ] what the CUSUM's h adds for the telescoping quantization error
  double quantization_sigma = 0.0;   //!< [σ] per parity axis: 1σ of one sample's quantization error term
  Eigen::Vector3d arw_sq_rad2_s;     //!< [rad²/s] N² per body axis of the rate estimate
  Eigen::Vector3d bias_sigma_rad_s;  //!< [rad/s] 1σ rate bias per body axis left by the calibration
  double chi2_threshold = 0.0;       //!< instantaneous χ² threshold
  double jump_threshold = 0.0;       //!< one-epoch jump χ² threshold
  double spread_threshold = 0.0;     //!< the parity spread's χ² threshold (its block values' cap)
  double cusum_k = 0.0;              //!< [σ] CUSUM reference
  double cusum_h = 0.0;              //!< [σ] CUSUM threshold
  double bias_wander_sigma = 0.0;    //!< [σ] per parity axis: the slowly wandering bias (B, K) in the parity
  //! the wander is averaged in h (true), or beyond the average's reach a tolerance e·s in the bound D (false)
  bool wander_averaged = true;
  //! [σ²] per parity axis and epoch: what the stated rate random walks K_i add to the parity's mean over one
  //! period, T²·Σ|w_i|²K_i²/d. Nonzero only where the wander is beyond the average's reach: the CUSUM then
  //! runs on the innovation of the tracked mean (ParityDetector), which is white under the model however
  //! long the run
  double wander_step_var = 0.0;
  //! [σ] what the tracked mean takes off the CUSUM's reference k + D: the tolerance e·s and the stated ramps
  //! over the horizon, less the tracker's lag behind the stated ramps (0 while `wander_step_var` is 0)
  double wander_relief = 0.0;
  //! [σ] the constant part D₀ of `calibration_bound`: the calibrated biases within calibration_error_sigmas
  //! (e) of their stated 1σ σ_β,i, e·√T·Σ_{i∈S} |w_i|·σ_β,i; the stated ramps over the horizon,
  //! √T·Σ|w_i|·R_i·H; and a wander beyond the average's reach, e·s (`wander_averaged` false)
  double calibration_bias_bound = 0.0;
  int level_epochs = 1;            //!< epochs an episode's parity level is averaged over before it is held
  double level_k = 0.0;            //!< [σ] reference of the CUSUM on the parity minus the held level
  double level_h = 0.0;            //!< [σ] its threshold
  double nominal_threshold = 0.0;  //!< χ²_d(1 − 1e-3): the slow parity mean back to nominal
  double glt_accept = 0.0;         //!< χ²_{d−1} quantile accepting a single-gyro hypothesis
  double glt_reject = 0.0;         //!< χ²_{d−1} quantile rejecting one
};

//! What the detectors' reference noise takes from each gyro's `noise:` section beyond its white noise N_i
//! (docs/fdi.md, "Noise model and normalized parity"). Empty vectors = none.
struct DetectorNoise {
  Eigen::VectorXd quantization_rad;   //!< [rad] angle quantization Q_i (0 if absent)
  Eigen::VectorXd bias_wander_rad_s;  //!< [rad/s] 1σ of the slowly wandering bias (`bias_wander_sigma`)
  //! [rad/s] what the stated rate ramp R moves the bias by over the horizon, R·horizon: deterministic, of
  //! either sign, it bounds the parity as the calibrated biases do (linearly, `calibration_bias_bound`)
  Eigen::VectorXd ramp_bound_rad_s;
  Eigen::VectorXd rate_random_walk_rad_s_rts;  //!< [rad/s/√s] the stated rate random walk K_i (0 if absent)
  Eigen::VectorXd rate_ramp_rad_s2;            //!< [rad/s²] |R_i|, the stated rate ramp (0 if absent)
  //! The calibration's stated 1σ (`sigma:`), for the rate-proportional parity term ("Calibration
  //! uncertainty")
  Eigen::VectorXd scale_rel_sigma;  //!< [-] 1σ of each scale factor relative to it (0 if absent)
  Eigen::Matrix3Xd axis_sigma;      //!< [-] 1σ of each axis component (columns per gyro; 0 if absent)
};
//! The calibration's `noise:` sections as the detectors see them (Q; B, K and R over the configured horizon).
DetectorNoise detector_noise(const Calibration& cal, const PipelineConfig& config);

//! [rad²/s²] variance of one sample of a gyro with white noise N [rad/√s] and angle quantization Q [rad] at
//! the sample period T [s]: N²/T + 2Q²/T² (a sample is (e_k − e_{k−1})/T of a quantized angle, var(e) = Q²).
//! The one formula of a sample's noise, for every test.
inline double sample_variance(double arw_rad_rts, double quantization_rad, double period_s) {
  return arw_rad_rts * arw_rad_rts / period_s +
         2.0 * quantization_rad * quantization_rad / (period_s * period_s);
}
//! [rad²/s²] variance of the mean of n consecutive samples: N²/(nT) and, the quantization errors telescoping
//! to (e_n − e_0)/(nT), 2Q²/(nT)² (n = 1: `sample_variance`).
inline double mean_variance(double arw_rad_rts, double quantization_rad, double period_s, double n) {
  return sample_variance(arw_rad_rts / std::sqrt(n), quantization_rad / n, period_s);
}
//! [rad²/s²] variance of the difference of two consecutive samples: 2N²/T and, of the quantized angle's
//! second difference (e_k − 2e_{k−1} + e_{k−2})/T, 6Q²/T².
inline double sample_difference_variance(double arw_rad_rts, double quantization_rad, double period_s) {
  return 2.0 * sample_variance(arw_rad_rts, quantization_rad, period_s) +
         2.0 * quantization_rad * quantization_rad / (period_s * period_s);
}

class SubsetCache {
 public:
  //! `geometry` weighted by each gyro's white rate noise N_i [rad/√s] (the rate estimate's weights);
  //! `bias_sigma_rad_s`: 1σ of each calibrated bias; `config` outlives the cache. `noise`: quantization and
  //! wandering bias per gyro, which the detectors' whitening adds once the sample period is known.
  SubsetCache(GyroGeometry geometry, Eigen::VectorXd bias_sigma_rad_s, const PipelineConfig& config,
              DetectorNoise noise = {});
  // by_mask_ points into subsets_: a copy would point into the original.
  SubsetCache(const SubsetCache&) = delete;
  SubsetCache& operator=(const SubsetCache&) = delete;
  SubsetCache(SubsetCache&&) noexcept = default;
  SubsetCache& operator=(SubsetCache&&) noexcept = default;

  //! The sample period T is known: thresholds follow from it. Every subset is built now for N ≤ 8 (a missing
  //! sample then never allocates); for larger N the full set and its leave-one-out subsets.
  void prepare(double period_s);
  bool ready() const { return period_s_ > 0.0; }
  double period_s() const { return period_s_; }
  double sqrt_period() const { return sqrt_period_; }

  //! As the parity's own spread shows them (parity_spread.hpp): every gyro's white rate noise N taken `white`
  //! (≥ 1) times its stated variance — every sum, the CUSUM, the GLT, sigma — and one sample's noise (N and
  //! the stated quantization) at least `sample` times the stated — the χ² and the jump test. Every subset
  //! built is rebuilt on them, in place.
  void set_noise_ratios(double white, double sample);
  //! [-] the white noise variance taken over the stated.
  double white_ratio() const { return white_scale_ * white_scale_; }
  //! [-] one sample's noise variance taken at least, over the stated.
  double sample_ratio() const { return sample_ratio_; }
  //! [σ²] the quantization's share of |Δ²|²/(6m) for the second difference Δ² of three consecutive m-epoch
  //! sums of the subset's normalized parity: 20·Σ_i |w_i|²·Q_i²/(T·6m) (the sums telescope to the ends' angle
  //! errors, e_c − 3e_b + 3e_a − e_0).
  double block_quantization(const Subset& s, int m) const;
  //! [-] the largest share of one sample's stated noise variance that is quantization, over the gyros.
  double quantization_share() const;

  //! The subset's constants, built on first use (only once `ready()`).
  const Subset& get(GyroMask mask) {
    if (mask < by_mask_.size() && by_mask_[mask] != nullptr) return *by_mask_[mask];
    const auto it = subsets_.find(mask);
    return it != subsets_.end() ? it->second : insert(mask);
  }
  //! The subset's constants if built already, else null.
  const Subset* find(GyroMask mask) const;
  //! Without a sample period, the full-rank test alone (at least 3 gyros spanning 3-D).
  bool observable(GyroMask mask) { return ready() ? get(mask).observable : tetra::gyro_count(mask) >= 3; }
  const GyroGeometry& geometry() const { return geometry_; }
  int gyro_count() const { return geometry_.gyro_count(); }

  //! [σ] bound on the normalized parity's calibration term at the body rate ω [rad/s] when every bias, scale
  //! factor and axis component of the subset's gyros is within `calibration_error_sigmas` (e) of its stated
  //! 1σ: e·√T·Σ_{i∈S} |w_i|·(σ_β,i + σ_s,i·|h_i·ω| + Σ_j σ_h,ij·|ω_j|) (docs/fdi.md, "Calibration
  //! uncertainty"), plus the stated ramps and an absorbed wander (`calibration_bias_bound`).
  double calibration_bound(const Subset& s, GyroMask mask, const Eigen::Vector3d& omega_rad_s) const {
    if (s.dof < 1) return 0.0;
    if (!calibration_sigma_) return s.calibration_bias_bound;  // no stated σ: ramps and wander only
    const Eigen::Vector3d w_abs = omega_rad_s.cwiseAbs();
    double sum = 0.0;
    for (int i = 0; i < gyro_count(); ++i) {
      if (!has_gyro(mask, i + 1)) continue;
      const double along = std::abs(geometry_.axes_B().row(i).dot(omega_rad_s));
      sum += s.parity_col_norm[i] * (scale_rel_sigma_[i] * along + axis_sigma_.col(i).dot(w_abs));
    }
    return s.calibration_bias_bound + config_->calibration_error_sigmas * sqrt_period_ * sum;
  }
  //! [σ²] d×d covariance of the normalized parity's calibration term at the body rate ω [rad/s] (the term is
  //! linear in ω, so this is also the covariance of its mean over epochs of mean rate ω) when each bias,
  //! scale factor and axis component of the subset's gyros errs by a Gaussian of `calibration_error_sigmas`
  //! (e) times its stated 1σ, independently: e²·T·Σ_{i∈S} w_i·w_iᵀ·(σ_β,i² + σ_s,i²·(h_i·ω)² + Σ_j
  //! σ_h,ij²·ω_j²), plus (e·σ_w)²·I for the wandering bias (σ_w = `bias_wander_sigma`: a unit's bias
  //! instability is known no better than its calibration) (docs/fdi.md, "GLT"). Written into `out` (resized
  //! to d×d). `with_bias` false: without the biases' term σ_β,i (a difference of two means, in which a
  //! constant bias cancels; ω is then the difference of their rates).
  void calibration_covariance(const Subset& s, GyroMask mask, const Eigen::Vector3d& omega_rad_s,
                              bool with_bias, Eigen::MatrixXd& out) const;
  //! [σ²·s²/rad²] 3d×3d covariance of the normalized parity's rate coefficients M (p = M·ω + …, d×3),
  //! stacked by parity axis (row j of M at 3j…3j+2), when each scale factor and axis component of the
  //! subset's gyros errs by a Gaussian of `calibration_error_sigmas` (e) times its stated 1σ: e²·T·Σ_{i∈S}
  //! (w_i·w_iᵀ) ⊗ (σ_s,i²·h_i·h_iᵀ + diag(σ_h,i²)) (docs/fdi.md, "A calibration that does not describe
  //! the unit"). Written into `out`; zero without stated σ.
  void rate_coefficient_covariance(const Subset& s, GyroMask mask, Eigen::MatrixXd& out) const;
  //! [rad/s] per body axis: the largest rate error the subset's scale factors and axes make at the body rate
  //! ω [rad/s] when each is within `calibration_error_sigmas` (e) of its stated 1σ, the detectors' bound:
  //! e·Σ_{i∈S} |H*(:, i)|·(σ_s,i·|h_i·ω| + Σ_j σ_h,ij·|ω_j|) (docs/fdi.md, "Calibration uncertainty"); the
  //! attitude's sigma integrates it. Zero without stated σ.
  Eigen::Vector3d calibration_rate_bound(const Subset& s, GyroMask mask,
                                         const Eigen::Vector3d& omega_rad_s) const {
    Eigen::Vector3d bound = Eigen::Vector3d::Zero();
    if (!calibration_sigma_ || !s.observable) return bound;
    const Eigen::Vector3d w_abs = omega_rad_s.cwiseAbs();
    for (int i = 0; i < gyro_count(); ++i) {
      if (!has_gyro(mask, i + 1)) continue;
      const double along = std::abs(geometry_.axes_B().row(i).dot(omega_rad_s));
      bound += s.pinv.col(i).cwiseAbs() * (scale_rel_sigma_[i] * along + axis_sigma_.col(i).dot(w_abs));
    }
    return config_->calibration_error_sigmas * bound;
  }

 private:
  const Subset& insert(GyroMask mask);
  void build(Subset& s, GyroMask mask) const;
  //! [σ] per parity axis: the wandering biases seen in the subset's normalized parity.
  double parity_bias_sigma(const Subset& s, GyroMask mask) const;
  //! A wander beyond the average's reach whose rate random walk is stated (`bounded` the design that bounds
  //! it): `wander_step_var` and `wander_relief`, and the design of the CUSUM on the tracked innovation (the
  //! bias instability's stationary wander averaged in its h); else `bounded`.
  CusumDesign track_wander(Subset& s, GyroMask mask, const CusumDesign& bounded) const;
  //! L⁻¹V with L Lᵀ = V diag(r) Vᵀ: the parity V of the subset whitened by per-gyro variances r.
  Eigen::MatrixXd whiten(const Eigen::MatrixXd& v, const Eigen::VectorXd& r) const;
  //! The quantization's sample and jump whitening, its CUSUM margin (needs `cusum_k`) and σ in the
  //! normalized parity (Subset).
  void add_quantization(Subset& s, const Eigen::MatrixXd& v, GyroMask mask) const;
  //! [σ] gyro i's bound on the quantization term of a parity sum, |W_i|·√3·Q_i/√T.
  double quantization_bound(const Subset& s, int i) const;
  //! [σ] what a CUSUM of reference `k` adds to its h for the telescoping quantization error.
  double quantization_margin(const Subset& s, GyroMask mask, double k) const;

  GyroGeometry geometry_;              //!< weighted by N_i
  Eigen::VectorXd bias_sigma_rad_s_;   //!< [rad/s] per gyro
  Eigen::VectorXd quantization_rad_;   //!< [rad] per gyro (zeros when none)
  Eigen::VectorXd bias_wander_rad_s_;  //!< [rad/s] per gyro (zeros when none)
  Eigen::VectorXd ramp_bound_rad_s_;   //!< [rad/s] per gyro, R·horizon (zeros when none)
  Eigen::VectorXd rrw_rad_s_rts_;      //!< [rad/s/√s] per gyro, K (zeros when none)
  Eigen::VectorXd ramp_rad_s2_;        //!< [rad/s²] per gyro, |R| (zeros when none)
  Eigen::VectorXd scale_rel_sigma_;    //!< [-] per gyro (zeros when none)
  Eigen::Matrix3Xd axis_sigma_;        //!< [-] per gyro and component (zeros when none)
  bool calibration_sigma_ = false;     //!< some bias, scale factor or axis has a stated σ > 0
  const PipelineConfig* config_;       //!< owned by the pipeline, outlives the cache
  double period_s_ = 0.0;
  double sqrt_period_ = 0.0;
  double white_scale_ = 1.0;   //!< [-] √ of the white noise variance taken over the stated
  double sample_ratio_ = 1.0;  //!< [-] one sample's noise variance taken at least, over the stated
  std::unordered_map<GyroMask, Subset> subsets_;
  //! For N ≤ 8: each built subset by its mask (the map's elements never move), a lookup without hashing.
  std::vector<const Subset*> by_mask_;
};

//! [rad/s] 1σ of a gyro's slowly wandering bias over the detectors' horizon: the stationary σ of the
//! bias-instability process (kBiasWanderPerB·B) and the rate random walk over `horizon_s` (K·√horizon), in
//! quadrature. B [rad/s], K [rad/s/√s]. The rate ramp is no random term: DetectorNoise::ramp_bound_rad_s.
double bias_wander_sigma(double bias_instability_rad_s, double rate_random_walk_rad_s_rts, double horizon_s);
//! σ_b / B: the stationary σ of a first-order Gauss–Markov bias whose Allan deviation peaks at the IEEE 952
//! floor 0.664·B (the simulator's bias-instability model, docs/sim.md).
inline constexpr double kBiasWanderPerB = kGaussMarkovSigmaPerB;

//! p_r = scale·Σ_{i∈mask} W(r, i)·v_i for the first `dof` rows of W; returns Σ p_r². The one parity kernel.
inline double apply_whitened(const Eigen::MatrixXd& w, int dof, GyroMask mask, const double* v, double scale,
                             double* p) {
  const int n = static_cast<int>(w.cols());
  double sum_sq = 0.0;
  for (int r = 0; r < dof; ++r) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i) {
      if (has_gyro(mask, i + 1)) acc += w(r, i) * v[i];
    }
    p[r] = acc * scale;
    sum_sq += p[r] * p[r];
  }
  return sum_sq;
}

//! Moves p[0..dof) towards 0 by `bound` along its direction (0 when |p| ≤ bound); returns the new Σ p_r².
//! A term of norm ≤ bound added to noise n then leaves |p| ≤ |n|: the calibration's dead zone.
inline double shrink_by(double* p, int dof, double bound, double sum_sq) {
  if (!(bound > 0.0)) return sum_sq;
  const double norm = std::sqrt(sum_sq);
  const double f = norm > bound ? 1.0 - bound / norm : 0.0;
  for (int r = 0; r < dof; ++r) p[r] *= f;
  return sum_sq * f * f;
}

//! The subset's normalized parity (`Subset::parity`) of v.
inline double apply_parity(const Subset& s, GyroMask mask, const double* v, double scale, double* p) {
  return apply_whitened(s.parity, s.dof, mask, v, scale, p);
}

//! ω = Σ_{i∈mask} H*(:, i)·v_i. The one rate kernel.
inline Eigen::Vector3d apply_pinv(const Eigen::Matrix3Xd& pinv, GyroMask mask, const double* v) {
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < pinv.cols(); ++i) {
    if (has_gyro(mask, static_cast<int>(i) + 1)) w += pinv.col(i) * v[i];
  }
  return w;
}

}  // namespace tetra::fdi::detail
