#pragma once
// Rate and attitude (docs/fdi.md, "Per epoch" 4 and 7, "Attitude filter" and "Attitude uncertainty"): the
// weighted least-squares rate over the usable gyros corrected by the filter's bias estimates, the trapezoid
// propagation of the attitude, the filter (mekf.hpp) that carries its covariance and takes the reference
// samples, and the bound of an unresolved fault or of a lost rate (added to the filter's σ).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "bias_snapshots.hpp"
#include "epoch_frame.hpp"
#include "gyro_series.hpp"
#include "mekf.hpp"
#include "subset_cache.hpp"
#include "tetra/core/attitude.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

//! [rad/s] per axis: the rate error under every single-gyro hypothesis of the subset, gyro i carrying the
//! fault f_i = wᵢᵀp̄/|wᵢ|² (p̄ the parity EMA), which moves the estimate by H*(:, i)·f_i; the per-axis maximum.
Eigen::Vector3d fault_rate_bound(const Subset& s, const Eigen::VectorXd& parity_ema, double sqrt_period);

//! [rad/s] per axis, the largest rate error of the solution over `used` — `full` without the gyros the jump
//! test left out, no parity of its own — under every single-gyro hypothesis of `full`'s normalized parity
//! `p`: gyro i of `used` carrying f_i = wᵢᵀp/|wᵢ|² (wᵢ its column of `full`'s parity) moves that solution by
//! H*_used(:, i)·f_i; a left-out gyro carrying it moves it by nothing.
Eigen::Vector3d unchecked_rate_bound(const Subset& full, const Subset& used, const Eigen::VectorXd& p,
                                     double sqrt_period);

//! [rad/s] the largest single-gyro fault size f_i = wᵢᵀp̄/|wᵢ|² over the gyros of the subset.
double fault_size_bound(const Subset& s, const Eigen::VectorXd& parity_ema, double sqrt_period);

//! [rad] per axis: the angle error a fault on gyro `id` caused since `span_s` ago, from the parity EMA.
Eigen::Vector3d fault_angle_error(const Subset& s, int id, const Eigen::VectorXd& parity_ema,
                                  double sqrt_period, double span_s);

//! The filter's noise model of every gyro: N and the calibration's bias σ from the pipeline's constants, K
//! and B from the calibration's `noise:` section, T_c from the configuration.
std::vector<GyroNoiseModel> noise_models(const Calibration& cal, const GyroSeries& series,
                                         const PipelineConfig& config);

//! What a reference sample did.
enum class ReferenceUse { kInitialized, kAccepted, kRejected, kReinitialized };

class RateAttitude {
 public:
  RateAttitude(const PipelineConfig& config, std::vector<GyroNoiseModel> gyros);

  //! The rate estimate of the usable gyros of `s` (kept when the subset is not observable).
  void measure(const Subset& s, const EpochFrame& frame);
  //! Before the sample period is known (first epoch): the estimate straight from the geometry.
  bool measure_unprepared(const GyroGeometry& geometry, const EpochFrame& frame);
  //! Propagates over the epoch with `sol` the solution's subset (`fallback`: the active set's, used only when
  //! `sol` is not observable), `fault_bound_rad_s` the bound of an unresolved fault and `period_s` the sample
  //! period (the trapezoid's curvature correction, docs/fdi.md "Per epoch" 7).
  void propagate(const EpochFrame& frame, const Subset& sol, const Subset* fallback,
                 const Eigen::Vector3d& fault_bound_rad_s, double period_s);
  //! Ends the epoch: the published rate and the previous rate for the next trapezoid.
  void finish_epoch() { omega_prev_ = omega_meas_; }

  //! A reference sample: the first one sets the attitude; later ones update the filter (gated). A run of
  //! gate rejections sets the attitude again only when `may_reinitialize` (the gyros cannot vouch for
  //! theirs).
  ReferenceUse reference(const Quaternion& q_ref_RB, bool may_reinitialize = true);
  //! The innovation `z` [rad] a reference sample would have against the attitude propagated to this epoch
  //! (the rate of this epoch, `dt_s`) and its covariance `S` [rad²]: the filter's attitude covariance, the
  //! bound of a fault or lost rate, the reference's σ. False before the first sample.
  bool predict_reference(const Quaternion& q_ref_RB, double dt_s, double period_s, Eigen::Vector3d& z,
                         Eigen::Matrix3d& S) const;
  //! The epoch's normalized parity `p` over the subset `s` into the filter's biases — once a reference sample
  //! has been seen (without one the attitude stays the gyros' alone).
  void parity(const Subset& s, const Eigen::VectorXd& p, double sqrt_period);
  bool reference_aided() const { return reference_seen_; }
  //! A fault episode opened with fault size bound `sigma_rad_s`: with the reference, the filter's slow bias
  //! states open up to take it (the reference and the parity then tell which gyro).
  void fault_opened(double sigma_rad_s) {
    if (reference_seen_) mekf_.open_fault_hypothesis(sigma_rad_s);
  }

  //! With the reference: a copy of the filter's bias states (at most once a second, none while held).
  void snapshot_biases(std::int64_t now_ns) {
    if (reference_seen_) snapshots_.take(now_ns, mekf_);
  }
  //! A fault episode began at `onset_ns`: the copy before it is held for `repair_biases`.
  void hold_biases(std::int64_t onset_ns) {
    if (reference_seen_) snapshots_.hold(onset_ns);
  }
  void release_biases() { snapshots_.release(); }
  //! After an isolation: the bias states of `gyros` go back to the held copy (or the newest before
  //! `onset_ns`), propagated to `now_ns` — what the fault leaked into them is undone (docs/fdi.md).
  void repair_biases(GyroMask gyros, std::int64_t onset_ns, std::int64_t now_ns) {
    if (reference_seen_) snapshots_.restore(mekf_, gyros, onset_ns, now_ns);
    snapshots_.release();
  }

  //! Gyro `id` leaves the solution (its bias states freeze) or comes back (at its prior).
  //! Either changes the solution's gyro set: the next step takes no slope across the two sets (their rates
  //! differ by the fault, not by the motion; docs/fdi.md, "Per epoch" 7).
  void freeze(int id) {
    mekf_.freeze(id);
    set_changed_ = true;
  }
  void thaw(int id) {
    mekf_.thaw(id);
    set_changed_ = true;
  }

  void add_bound(const Eigen::Vector3d& angle_rad) { propagator_.add_bound(angle_rad); }
  //! [rad] on every axis: the most the trapezoid across a gap of `tau_s` can miss, a·τ²/4 (the rate leaving
  //! its chord at a and coming back), a the larger of the configured bound and the norm of the acceleration
  //! the gyros saw before the gap beyond its noise (`s`: the gyros in use).
  double gap_bound_rad(double tau_s, const Subset& s) const;
  //! Adds a variance [rad²] per axis to the filter's attitude (e.g. what a rejected reference put in).
  void add_variance(const Eigen::Vector3d& var_rad2) { mekf_.add_attitude_variance(var_rad2); }
  void reset(const Quaternion& q0_RB);
  //! [rad/s] the trapezoid's curvature correction over the step `dt_s` to this epoch: −(T²/12)·(s_k −
  //! s_{k−1})/Δt with s the rate's slope over a step and T `period_s` (zero before two steps).
  Eigen::Vector3d curvature_rad_s(double dt_s, double period_s) const;

  //! [rad/s] last rate estimate, Earth rate included.
  const Eigen::Vector3d& omega_meas_B() const { return omega_meas_; }
  //! [rad/s] rate of B relative to the reference frame (Earth rate removed in ground mode).
  Eigen::Vector3d omega_BR_B() const { return omega_meas_ - propagator_.earth_rate_B(); }
  Eigen::Vector3d earth_rate_B() const { return propagator_.earth_rate_B(); }
  const Quaternion& q_RB() const { return propagator_.q_RB(); }
  //! [rad] 1σ per axis of the reference samples from now on (reference_sigma_arcsec until re-estimated).
  void set_reference_sigma_rad(double sigma_rad) { sigma_ref_rad_ = sigma_rad; }
  //! [rad] 1σ per body axis: the filter's, with the bound of a fault or a lost rate in quadrature.
  Eigen::Vector3d sigma_rad() const;
  const Mekf& filter() const { return mekf_; }
  Mekf& filter() { return mekf_; }
  //! The last reference sample's χ² (3 dof); 0 before any.
  double reference_chi2() const { return last_chi2_; }
  //! [rad] body: the last accepted reference update's attitude correction δθ
  const Eigen::Vector3d& reference_correction_rad() const { return last_correction_rad_; }
  //! [rad/s] body: the bias estimates' projection the attitude was last propagated with, H*·b̂
  const Eigen::Vector3d& rate_bias_B_rad_s() const { return correction_; }

 private:
  const PipelineConfig& config_;
  AttitudePropagator propagator_;  //!< the quaternion, and the bound (its noise inputs stay zero)
  Mekf mekf_;
  BiasSnapshots snapshots_;  //!< the bias states before a fault, for their repair at its isolation
  double gate_chi2_ = 0.0;   //!< χ²₃ quantile of the reference gate
  Eigen::Vector3d correction_ = Eigen::Vector3d::Zero();  //!< [rad/s] H*·b̂ of the last observable epoch
  bool reference_seen_ = false;
  double sigma_ref_rad_ = 0.0;  //!< [rad] 1σ of a reference sample per axis
  int rejected_run_ = 0;        //!< reference samples rejected in a row
  double last_chi2_ = 0.0;
  Eigen::Vector3d last_correction_rad_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d omega_prev_ = Eigen::Vector3d::Zero();  //!< [rad/s] previous epoch's estimate
  Eigen::Vector3d omega_meas_ = Eigen::Vector3d::Zero();  //!< [rad/s] last estimate (Earth rate included)
  Eigen::Vector3d slope_prev_ = Eigen::Vector3d::Zero();  //!< [rad/s²] the previous step's (ω_k − ω_{k−1})/Δt
  bool have_slope_ = false;
  bool set_changed_ = false;  //!< a gyro left or joined the solution since the last step
  //! [rad/s²] per axis: the largest |slope| of recent observable steps (decaying over
  //! design::accel_memory_s), so a lost rate's bound covers the acceleration the gyros saw when it exceeds
  //! the configured bound.
  Eigen::Vector3d accel_seen_ = Eigen::Vector3d::Zero();
  double accel_decay_dt_s_ = -1.0;  //!< [s] the step of accel_decay_
  double accel_decay_ = 1.0;        //!< e^{−Δt/design::accel_memory_s}
  std::int64_t lost_since_ns_ = -1;
  std::int64_t measured_ns_ = -1;  //!< [ns] the last epoch whose rate was measured
};

}  // namespace tetra::fdi::detail
