#pragma once
// The attitude reference as a sensor that can fail (docs/fdi.md, "Reference consistency"). Every reference
// sample's innovation against the gyro-propagated attitude, z with covariance S (the filter's attitude
// covariance, any fault bound and the reference's configured σ), is tested before anything uses the sample:
//
//   jump  one sample:          zᵀS⁻¹z                        > χ²₃(1 − p)
//   nis   the window's sum:    Σ zᵀS⁻¹z over m samples        > χ²_{3m}(1 − p)
//   lag   z = a − ω·τ fitted over the window (a per-axis offset, τ common): τ̂²/var(τ̂) > χ²₁(1 − p)
//   bias  the long window's weighted mean innovation: Σ_a (Σ z_a/S_aa)²/Σ 1/S_aa > χ²₃(1 − p)
//   step  a step the filter is absorbing, fitted over the last samples (reference_step.hpp) > χ²₃(1 − p/M)
//
// p = the budget's kReferenceCheck share per sample. Windows are consecutive blocks (the nis and lag
// tests' of reference_window_s, the bias test's of reference_bias_window_s), each test evaluated at
// every sample over its block so far. Without a gyro fault the innovations are white with covariance S (the
// filter's model), so each statistic has the stated distribution; what a fault of the reference does to them
// is in docs/fdi.md. The tests decide nothing: the caller writes their ledger rows and the arbiter decides
// (arbitrate_reference: rejected only while the gyros' parity rejects every single-gyro hypothesis and a
// common drift is ruled out). A rejected reference's samples are no longer used (sigma grows with the gyro
// propagation) until they pass every test for one block, reference_window_s. With no call, a failed
// test is reported (`inconsistent`) and nothing else changes.
// A reference rejected for `nis` alone is noisier than configured: while rejected, its noise is re-estimated
// from the differences of its successive innovations (at their upper confidence bound, once a block, when
// the lower bound shows it noisier than configured); at most reference_noise_max_factor × the configured σ,
// the tests go on against that σ, and the reference is used again with it once they pass (sigma_rad()).

#include <cstdint>
#include <limits>
#include <optional>

#include <Eigen/Core>

#include "reference_step.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/ledger.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

//! What one sample's tests show, before anything is decided: the evidence the ledger's rows are written from.
struct ReferenceEvidence {
  std::optional<ReferenceCheck> failed;  //!< the first test that failed over the blocks, or none
  double bias_statistic = 0.0;           //!< the bias test's χ²₃ at this sample (0 when not reached)
  //! [rad²] per axis Σz² − ΣS_aa of the samples used in the nis block before this sample, and their count
  Eigen::Vector3d used_excess_rad2 = Eigen::Vector3d::Zero();
  int used_count = 0;
  //! The step test failed: its best step beside the best ramp over its window (a drift of the gyros makes
  //! a ramp, ReferenceStep::ramp_fit)
  std::optional<RampFit> ramp;
};

//! What the sample's decision did.
struct ReferenceVerdict {
  bool use = true;                         //!< the sample may update the filter and the reference windows
  std::optional<ReferenceCheck> rejected;  //!< the reference was rejected at this sample, and why
  bool reaccepted = false;                 //!< the reference is used again from this sample on
  //! A test failed and the arbiter made no call (a gyro's hypothesis stands beside the reference's: no
  //! parity or an open episode): the reference or a gyro is wrong, and the data cannot tell which.
  std::optional<ReferenceCheck> inconsistent;
  Eigen::Vector3d contamination_rad2 = Eigen::Vector3d::Zero();  //!< rejected: what the used samples put in
  //! [rad] rejected for `step`: the step's size |ĉ|, which the reference's samples carry from then on (the
  //! caller's ReferenceBudget learns it)
  double step_rad = 0.0;
  //! The gyros' common drift matched (ReferenceDecision::kMatchDrift): the sample is used, and the caller
  //! opens the gyros' bias model by what the test saw — [rad] its weighted mean innovation per axis over its
  //! block, and [s] the block's span to this sample; for a step a ramp explains (`from_ramp`), the mean a
  //! ramp's rate b makes over its span T, b·T/2, and T.
  bool drift = false;
  bool from_ramp = false;
  Eigen::Vector3d bias_mean_rad = Eigen::Vector3d::Zero();
  double bias_span_s = 0.0;
};

class ReferenceConsistency {
 public:
  explicit ReferenceConsistency(const PipelineConfig& config);

  void reset();    //!< absent, windows empty, the configured σ
  void reopen();   //!< absent, windows empty: judged afresh, with the σ it has (re-estimated or configured)
  void restart();  //!< windows empty (the gyro set changed, an episode ended); the state kept

  //! One sample at `now_ns`: its innovation `z_rad` with covariance `S` and the body rate `omega_rad_s` at
  //! its time, into the tests' blocks; what they show (nothing decided). `calibration_rad_s` [rad/s] per
  //! axis: the rate error the calibration's tolerance allows at that rate
  //! (SubsetCache::calibration_rate_bound); `steps_judged`: the gyros vouch for their attitude over the step
  //! test's window (parity, no episode) — without, a gyro's noise or ramp walks the attitude in steps of its
  //! own, and the window starts afresh.
  ReferenceEvidence test_sample(std::int64_t now_ns, const Eigen::Vector3d& z_rad, const Eigen::Matrix3d& S,
                                const Eigen::Vector3d& omega_rad_s, const Eigen::Vector3d& calibration_rad_s,
                                bool steps_judged);
  //! Whether the arbiter decides this sample: the reference is not rejected (a rejected one is used again
  //! here, once its samples pass every test for a block).
  bool judged() const { return state_ != ReferenceState::kRejected; }
  //! The sample tested last, under the arbiter's `decision` (ignored while rejected); `drift_threshold` the
  //! bias statistic a drift was matched at (the noise_model event's).
  ReferenceVerdict decide(std::int64_t now_ns, const Eigen::Vector3d& z_rad, const Eigen::Matrix3d& S,
                          const ReferenceEvidence& evidence, ReferenceDecision decision,
                          double drift_threshold);
  //! No sample for reference_window_s: absent (an accepted reference only; a rejected one stays rejected).
  void absent() {
    if (state_ == ReferenceState::kAccepted) state_ = ReferenceState::kAbsent;
  }

  ReferenceState state() const { return state_; }
  //! [rad] 1σ per axis of a reference sample: reference_sigma_arcsec, or the re-estimated noise.
  double sigma_rad() const { return sigma_rad_; }
  //! The window's NIS per degree of freedom (Σ zᵀS⁻¹z / 3m: 1 for a consistent reference); 0 before any.
  double windowed_nis() const { return nis_per_dof_; }
  //! The statistic of the last test that failed (or was the last one computed), its χ² threshold and
  //! degrees of freedom: the ledger rows of a decision.
  struct CheckValue {
    double statistic = 0.0;
    double threshold = 0.0;
    int dof = 0;
  };
  const CheckValue& failed_check() const { return failed_; }
  //! The bias block empty from `now_ns` on (a drift matched elsewhere: the mean it saw is accounted for).
  void restart_bias_block(std::int64_t now_ns);
  //! The bias statistic at the last drift match and its threshold (the noise_model event's).
  const CheckValue& drift_check() const { return drift_check_; }
  //! [rad] the bias test's weighted mean innovation per axis over its block so far, and [s] the block's span
  //! to `now_ns` (0 before a sample).
  Eigen::Vector3d bias_mean_rad() const { return bias_swz_.cwiseQuotient(bias_sw_); }
  std::int64_t bias_start_ns() const { return bias_start_ns_; }  //!< the bias block's start (−1: none)
  //! The bias block's mean at the last sample beyond what a good reference shows (χ²₃(1 −
  //! design::reference_mean_accept_probability)) and not yet decided: Href (or Hdrift) not consistent.
  bool mean_unresolved() const { return mean_unresolved_; }
  double bias_span_s(std::int64_t now_ns) const {
    return bias_start_ns_ < 0 ? 0.0 : ns_to_seconds(now_ns - bias_start_ns_);
  }

 private:
  //! The first test that fails over the blocks with this sample in, or none.
  //! (`bias_statistic` the bias test's χ²₃, left as it is when the test is not reached).
  std::optional<ReferenceCheck> test(std::int64_t now_ns, const Eigen::Vector3d& z, const Eigen::Vector3d& w,
                                     double nis, const Eigen::Vector3d& omega,
                                     const Eigen::Vector3d& calibration_rad_s, double& bias_statistic);
  //! The sample into the blocks (the nis and lag block, the bias block, the step test's window), each
  //! started afresh once it has run its length.
  void accumulate(std::int64_t now_ns, const Eigen::Vector3d& z, const Eigen::Vector3d& w, double nis,
                  const Eigen::Vector3d& omega, const Eigen::Vector3d& calibration_rad_s);
  void restart_blocks(std::int64_t now_ns);
  //! A sample used: its innovation's second moment against the predicted one, into the block.
  void add_used(const Eigen::Vector3d& z_rad, const Eigen::Matrix3d& S);
  //! Rejected at `now_ns` for `why`: the noise estimate and the blocks start afresh.
  void reject(std::int64_t now_ns, ReferenceCheck why);
  //! A sample while rejected: left out, or used again once every test passed for a block.
  ReferenceVerdict judge_rejected(std::int64_t now_ns, const Eigen::Vector3d& z_rad, const Eigen::Matrix3d& S,
                                  const std::optional<ReferenceCheck>& failed);
  //! Rejected for `nis`: this sample into the noise estimate; true when a block's estimate raised sigma_rad_.
  bool reestimate_noise(std::int64_t now_ns, const Eigen::Vector3d& z);

  const PipelineConfig& config_;
  double jump_chi2_ = 0.0;         //!< χ²₃(1 − p)
  double lag_chi2_ = 0.0;          //!< χ²₁(1 − p)
  double mean_accept_chi2_ = 0.0;  //!< χ²₃(1 − design::reference_mean_accept_probability)
  bool mean_unresolved_ = false;   //!< the bias statistic beyond mean_accept_chi2_ at the last sample
  CheckValue drift_check_;         //!< the bias statistic at the last drift match, and its threshold
  double z_tail_ = 0.0;            //!< Φ⁻¹(1 − p), for the Wilson–Hilferty χ²_{3m} quantile
  ReferenceState state_ = ReferenceState::kAbsent;
  std::int64_t consistent_since_ns_ = 0;  //!< rejected: every sample since passed every test
  double nis_per_dof_ = 0.0;
  Eigen::Vector3d lag_offset_rad_ = Eigen::Vector3d::Zero();  //!< [rad] |ω̄·τ̂| of the block so far
  double lag_s_ = 0.0;                                        //!< [s] τ̂ of the block so far
  double lag_den_ = 0.0;  //!< [1/rad²·(rad/s)²] Σ_a Σw(ω − ω̄)² of the block so far: 1/var(τ̂)
  double rejected_lag_s_ = 0.0;      //!< [s] |τ̂| when rejected for `lag` (0: another reason)
  double reaccept_den_ = 0.0;        //!< rejected: Σ of lag_den_ over the blocks completed since consistent
  double sigma_config_rad_ = 0.0;    //!< [rad] reference_sigma_arcsec
  double sigma_rad_ = 0.0;           //!< [rad] the σ the samples are judged and used with
  bool rejected_for_nis_ = false;    //!< rejected, and for `nis`
  std::int64_t noise_start_ns_ = 0;  //!< the noise estimate's block
  Eigen::Vector3d noise_sum_ = Eigen::Vector3d::Zero();  //!< [rad] Σ of successive innovations' differences
  Eigen::Vector3d noise_sum_sq_ = Eigen::Vector3d::Zero();  //!< [rad²] Σ of their squares
  int noise_count_ = 0;                                     //!< differences in the block
  Eigen::Vector3d last_z_ = Eigen::Vector3d::Zero();  //!< [rad] the previous rejected sample's innovation
  bool have_last_z_ = false;
  bool noise_explained_ = false;      //!< the last block's estimate is within sigma_rad_
  CheckValue failed_;                 //!< the last test's statistic and threshold
  ReferenceStep step_;                //!< the step test's window
  StepFit step_fit_;                  //!< its best onset at the last sample
  std::int64_t last_sample_ns_ = -1;  //!< the previous sample tested (the rotation since, for the step test)

  // the nis and lag block (reference_window_s)
  std::int64_t block_start_ns_ = -1;
  int block_count_ = 0;
  double block_nis_ = 0.0;
  Eigen::Vector3d sw_, swo_, swz_, swoo_, swoz_;  //!< per axis Σw, Σwω, Σwz, Σwω², Σwωz (w = 1/S_aa)
  Eigen::Vector3d szz_;                           //!< per axis Σz² of the samples used
  Eigen::Vector3d sss_;                           //!< per axis ΣS_aa of the samples used
  // the bias block (reference_bias_window_s)
  std::int64_t bias_start_ns_ = -1;
  int bias_count_ = 0;
  Eigen::Vector3d bias_sw_, bias_swz_;
};

}  // namespace tetra::fdi::detail
