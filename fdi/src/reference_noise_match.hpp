#pragma once
// Three gyros and a reference (docs/fdi.md, "Reference consistency", "Three gyros: a second fault"): no parity
// is left, so a gyro whose noise rises (or whose bias starts to ramp) shows only in the reference's
// innovations, along that gyro's column h_i of the rate solution H* (a rate error f on gyro i turns the
// attitude by h_i·f). Per gyro, the innovation z projected on d_i = h_i/|h_i| is tested against its predicted
// variance s_i = d_iᵀ·S·d_i by a CUSUM of the variance ratio's log-likelihood, designed for a doubling:
//
//   g_i ← max(0, g_i + ½·((1 − 1/ρ)·(d_iᵀz)²/s_i − ln ρ)),   ρ = 2;   detected when g_i > ln(1/p)
//
// (p = reference_check_false_alarm_probability: the mean run length without a fault is at least 1/p samples,
// Wald's bound). Its mean step is −0.10 without a fault and +0.25·R − 0.35 when the innovations' variance along
// d_i is R times the predicted. From the detection on, the gyro's white rate noise in the filter is matched to
// the innovations (covariance matching): m_i, the mean of (d_iᵀz)² over reference_check_window_s, less the
// reference's variance r is the attitude's a-priori error variance along d_i, P; a filter whose step noise
// along d_i is q·T (T the sample interval) has that a-priori variance at steady state when q·T = P²/(P + r),
// so the gyro's noise becomes N_i² + max(0, q − q_model)/|h_i|² (q_model: the model's along d_i), at most
// (kMaxNoiseRatio² − 1)·N_i² above the model. At the detection the attitude's variance along d_i grows by
// m_i − s_i (what the error has already done beyond the model). The gyro is never excluded: three gyros are
// the rate.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "tetra/fdi/config.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

class Mekf;

//! A gyro whose innovations exceed the model: detected at this sample.
struct NoiseFinding {
  int gyro = 0;            //!< 1..N
  double statistic = 0.0;  //!< [-] m_i/s_i: the innovations' mean square along d_i over the predicted
};

class ReferenceNoiseMatch {
 public:
  //! The largest white rate noise the filter takes on, as a multiple of the model's N.
  static constexpr double kMaxNoiseRatio = 30.0;

  ReferenceNoiseMatch(const PipelineConfig& config, int gyro_count);

  //! No gyro detected, the statistics empty (a reset, a change of the gyros used).
  void reset();

  //! One reference sample used by the filter at `now_ns`, before its update: its innovation `z_rad` with
  //! covariance `S`, the rate solution `pinv` (3×N) over exactly three gyros `mask`, the filter (its model's
  //! noise; it receives the matched noise). Returns the gyro detected at this sample, if one is.
  std::optional<NoiseFinding> observe(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                      const Eigen::Matrix3d& S, const Eigen::Matrix3Xd& pinv, GyroMask mask,
                                      Mekf& filter);

  //! Gyro `id` (1..N) detected and its noise matched since.
  bool matched(int id) const { return matched_[static_cast<std::size_t>(id - 1)]; }
  //! A test of the reference failed with three gyros (the data cannot tell which gyro): every gyro's noise
  //! is matched from the next sample on.
  void match_all();

 private:
  //! [rad²/s] gyro index `i`'s noise beyond the model from its mean square along `d` (|h_i|² = `h2`, sample
  //! interval `T`): the covariance-matching start.
  double mapped_noise(int i, const Eigen::Vector3d& d, double h2, double T, const Eigen::Matrix3Xd& pinv,
                      GyroMask mask, const Mekf& filter) const;

  double false_alarm_ = 0.0;   //!< p per sample
  double window_s_ = 30.0;     //!< [s] the mean square's time constant
  double reference_var_ = 0.0; //!< [rad²] r, the reference's variance per axis
  GyroMask mask_ = 0;          //!< the three gyros of the statistics
  std::int64_t last_ns_ = -1;  //!< the last sample's time
  std::int64_t block_start_ns_ = -1;  //!< the CUSUM block's first sample
  int block_samples_ = 0;             //!< samples in the block
  std::vector<double> cusum_;          //!< [-] g_i
  std::vector<double> mean_square_;    //!< [rad²] m_i
  std::vector<double> block_z_;        //!< [rad] Σ d_iᵀz over the block
  std::vector<double> block_s_;        //!< [rad²] Σ s_i over the block
  std::vector<bool> matched_;
  std::vector<double> ratio_;  //!< [-] the matched noise variance over the model's, N'²/N², 1..kMaxNoiseRatio²
};

}  // namespace tetra::fdi::detail
