#pragma once
// Detection on the normalized parity (docs/fdi.md, "Detection"): the instantaneous χ² on every epoch's subset
// that has parity, and the CUSUM — two-sided for d = 1, Crosier's vector form for d ≥ 2 — on the full active
// subset only. During an episode a second CUSUM runs on the parity minus the episode's held level: a new
// fault while the first persists is a new detection (test `level`). Also keeps the 2-s EMA of the parity,
// the size estimate of an unresolved fault.

#include <cstdint>

#include <Eigen/Core>

#include "epoch_frame.hpp"
#include "subset_cache.hpp"

namespace tetra::fdi::detail {

struct Detection {
  bool alarm = false;
  DetectionTest test = DetectionTest::kNone;
  double statistic = 0.0;
  std::int64_t onset_index = 0;  //!< estimated first faulty epoch (the CUSUM's change time)
  bool cusum_ran = false;        //!< the CUSUM saw this epoch (full active subset present)
  double threshold = 0.0;        //!< the alarm's threshold, in the statistic's unit
  int dof = 0;                   //!< χ²: its degrees of freedom
};

//! One CUSUM on d-dimensional normalized parity: two-sided for d = 1, Crosier's vector form for d ≥ 2, with
//! its change-time estimate (where it last left zero) and, for d ≥ 2, Σ p since then.
class Cusum {
 public:
  explicit Cusum(Eigen::Index dmax);
  //! Statistic, sum and change times to zero; the next change time is epoch `next_index`.
  void clear(std::int64_t next_index);
  //! The statistic to zero (after an alarm).
  void zero();
  //! One epoch: the first d entries of p; returns the statistic, `onset` its change time.
  double step(const Eigen::VectorXd& p, int d, double k, std::int64_t index, std::int64_t& onset);
  const Eigen::VectorXd& sum() const { return sum_; }
  int count() const { return n_; }

 private:
  double pos_ = 0.0;
  double neg_ = 0.0;
  std::int64_t pos_start_ = 0;
  std::int64_t neg_start_ = 0;
  Eigen::VectorXd s_;    //!< d ≥ 2: Crosier's vector statistic
  Eigen::VectorXd sum_;  //!< Σ p since the vector statistic was last zero
  Eigen::VectorXd dp_;   //!< scratch
  int n_ = 0;
  std::int64_t start_ = 0;
};

class ParityDetector {
 public:
  //! `nominal_window_s`: time constant of the slow parity mean that tells when the evidence is back to
  //! nominal.
  explicit ParityDetector(int n_gyros, double nominal_window_s = 30.0);

  //! The epoch's parity over `frame.usable` (`s` its subset), the χ² test, and the CUSUMs when every active
  //! gyro is usable. Writes the statistics into `health`. `calibration_bound` D [σ]: the bound on the
  //! parity's calibration term at this epoch's rate (`SubsetCache::calibration_bound`): the parity
  //! (`parity()`, the χ²) is moved towards 0 by D, and the CUSUM, on the parity as it is, takes k + D as its
  //! reference.
  Detection update(const EpochFrame& frame, const Subset& s, GyroMask active, double sqrt_period,
                   double calibration_bound, Health& health);
  //! After an alarm: the CUSUM that raised it starts again from zero, so a persisting fault keeps alarming
  //! (and the main CUSUM's alarms during an episode leave the level test running).
  void restart_after_alarm();
  //! Everything back to zero; the next change time is epoch `next_index`. Ends the episode's level.
  void restart(std::int64_t next_index);
  //! An episode opened, or its level changed (a `level` detection): the level is the mean parity over the
  //! next `Subset::level_epochs`, then held, and the level test runs on the parity minus it.
  void open_episode();
  //! The episode ended (`cleared`): the level test stops until the next episode opens; its CUSUM's next
  //! change time is epoch `next_index`.
  void close_episode(std::int64_t next_index);

  //! This epoch's normalized parity (first `dof` entries).
  const Eigen::VectorXd& parity() const { return p_; }
  //! This epoch's normalized parity as measured, before the calibration bound moved it (the CUSUM's input).
  const Eigen::VectorXd& parity_measured() const { return p_raw_; }
  //! 2-s EMA of the normalized parity.
  const Eigen::VectorXd& parity_ema() const { return p_ema_; }
  //! The parity evidence is nominal: the slow mean (time constant `nominal_window_s`) of the full active
  //! subset's parity lies within its noise and the wandering bias, |p̄|² < χ²_d(1 − 1e-3)·(var_EMA + s²).
  //! False while the slow mean has not yet seen a full window since a restart.
  bool parity_nominal(const Subset& s) const;
  //! Σ p and its count since the vector CUSUM last left zero (d ≥ 2).
  const Eigen::VectorXd& vector_sum() const { return cusum_.sum(); }
  int vector_count() const { return cusum_.count(); }

 private:
  //! The slow mean's gain and variance (slow_beta_, slow_var_) for the step `dt_s` and the subset's
  //! quantization σ `qs`: taken again only when either changes.
  void slow_terms(double dt_s, double qs);
  //! The level test of an open episode: accumulate the level, then the CUSUM on p minus it.
  bool level_change(const Subset& s, std::int64_t index, Detection& d);
  //! The CUSUM's input: the parity as measured, or where the subset's wander is tracked
  //! (`Subset::wander_step_var` > 0) the innovation of the tracked mean m, (p − m)/√(1 + P⁻), white under the
  //! model however long the run; m follows the parity (a scalar Kalman filter of a random walk) outside an
  //! episode and is held during one, so a fault is not taken into it.
  const Eigen::VectorXd& cusum_input(const Subset& s);
  //! The tracked mean back to 0 with the wander over the horizon as its prior.
  void restart_wander() { wander_fresh_ = true; }

  GyroMask cusum_mask_ = 0;
  Cusum cusum_;
  Cusum level_cusum_;
  bool level_alarm_ = false;  //!< the last alarm was the level test's
  bool episode_ = false;
  bool level_held_ = false;
  int level_n_ = 0;
  Eigen::VectorXd level_;  //!< the episode's mean parity, summed then held
  Eigen::VectorXd p_ema_;
  Eigen::VectorXd p_slow_;  //!< EMA of the parity with time constant nominal_window_s_
  double nominal_window_s_ = 30.0;
  double slow_var_ = 0.0;    //!< [σ²] per axis: variance of p_slow_ without fault
  double slow_beta_ = 0.0;   //!< [-] the slow mean's gain at the step slow_dt_s_
  double slow_dt_s_ = -1.0;  //!< [s] the step, and the quantization σ, slow_beta_ and slow_var_ are for
  double slow_qs_ = -1.0;
  double slow_age_s_ = 0.0;  //!< [s] time the slow mean has run since it was last zeroed
  Eigen::VectorXd p_;
  Eigen::VectorXd p_raw_;  //!< this epoch's parity before the calibration bound moved it (the CUSUM's input)
  Eigen::VectorXd dp_;     //!< scratch
  Eigen::VectorXd wander_mean_;  //!< [σ] the tracked mean of the parity (tracked subsets only)
  Eigen::VectorXd wander_in_;    //!< its innovation, normalized (the CUSUM's input)
  double wander_var_ = 0.0;      //!< [σ²] per axis: the tracked mean's variance
  bool wander_fresh_ = true;     //!< the tracker starts again at the next epoch
};

}  // namespace tetra::fdi::detail
