#pragma once
// Detection on the normalized parity (docs/fdi.md, "Detection"): the instantaneous χ² on every epoch's subset
// that has parity, and the CUSUM — two-sided for d = 1, Crosier's vector form for d ≥ 2 — on the full active
// subset only. Also keeps the 2-s EMA of the parity, the size estimate of an unresolved fault.

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
};

class ParityDetector {
 public:
  //! `nominal_window_s`: time constant of the slow parity mean that tells when the evidence is back to
  //! nominal.
  explicit ParityDetector(int n_gyros, double nominal_window_s = 30.0);

  //! The epoch's parity over `frame.usable` (`s` its subset), the χ² test, and the CUSUM when every active
  //! gyro is usable. Writes the statistics into `health`.
  Detection update(const EpochFrame& frame, const Subset& s, GyroMask active, double sqrt_period,
                   Health& health);
  //! After an alarm: the CUSUM starts again from zero, so a persisting fault keeps alarming.
  void restart_after_alarm();
  //! Everything back to zero; the next change time is epoch `next_index`.
  void restart(std::int64_t next_index);

  //! This epoch's normalized parity (first `dof` entries).
  const Eigen::VectorXd& parity() const { return p_; }
  //! 2-s EMA of the normalized parity.
  const Eigen::VectorXd& parity_ema() const { return p_ema_; }
  //! The parity evidence is nominal: the slow mean (time constant `nominal_window_s`) of the full active
  //! subset's parity lies within its noise and the wandering bias, |p̄|² < χ²_d(1 − 1e-3)·(var_EMA + s²).
  //! False while the slow mean has not yet seen a full window since a restart.
  bool parity_nominal(const Subset& s) const;
  //! Σ p and its count since the vector CUSUM last left zero (d ≥ 2).
  const Eigen::VectorXd& vector_sum() const { return mc_sum_; }
  int vector_count() const { return mc_n_; }

 private:
  double scalar_cusum(double p, const Subset& s, std::int64_t index, std::int64_t& onset);
  double vector_cusum(const Subset& s, std::int64_t index, std::int64_t& onset);

  GyroMask cusum_mask_ = 0;
  double cusum_pos_ = 0.0;
  double cusum_neg_ = 0.0;
  std::int64_t cusum_pos_start_ = 0;  //!< epoch where the branch last left zero
  std::int64_t cusum_neg_start_ = 0;
  Eigen::VectorXd mcusum_;  //!< d ≥ 2: Crosier's vector CUSUM
  Eigen::VectorXd mc_sum_;  //!< Σ p since the vector CUSUM was last zero
  int mc_n_ = 0;
  std::int64_t mc_start_ = 0;
  Eigen::VectorXd p_ema_;
  Eigen::VectorXd p_slow_;  //!< EMA of the parity with time constant nominal_window_s_
  double nominal_window_s_ = 30.0;
  double slow_var_ = 0.0;    //!< [σ²] per axis: variance of p_slow_ without fault
  double slow_age_s_ = 0.0;  //!< [s] time the slow mean has run since it was last zeroed
  Eigen::VectorXd p_;
  Eigen::VectorXd dp_;  //!< scratch
};

}  // namespace tetra::fdi::detail
