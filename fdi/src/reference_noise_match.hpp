#pragma once
// Three gyros and a reference (docs/fdi.md, "Three gyros: a noise increase or a ramp"): no parity is left, so
// a gyro whose bias starts to ramp (or whose noise rises where its own level, own_noise_level.hpp, cannot
// show it) shows only in the reference's innovations, along that gyro's column h_i of the rate solution H* (a
// rate error f on gyro i turns the attitude by h_i·f). Per gyro, the innovations z projected on d_i =
// h_i/|h_i| are summed over blocks of design::reference_match_block_s (10 s); a block's u_i = (Σ d_iᵀz)²/Σ
// s_i (s_i = d_iᵀ·S·d_i) is χ²₁ while the filter's model holds (its innovations are white with covariance S)
// and grows when the attitude error wanders beyond the model (it is slow: the extra error is correlated over
// tens of seconds, so a block mean sees it where one sample, dominated by the reference's own noise, barely
// does). A CUSUM of the log-likelihood ratio for a block variance ρ times the predicted,
//
//   g_i ← max(0, g_i + ½·((1 − 1/ρ)·u_i − ln ρ)),   ρ = 4;   detected when g_i > ln(1/(p·n))
//
// (p = the budget's kReferenceNoiseMatch share per sample, n the block's samples: the mean run length without
// a fault is at least 1/(p·n) blocks, Wald's bound) names the gyro. From then on the gyro's white rate noise
// in the filter is N_i²·λ_i: λ_i starts where covariance matching puts it (m_i, the mean square of d_iᵀz over
// reference_window_s, less the reference's variance r is the a-priori error variance P along d_i; a
// step noise q·T along d_i has that steady state when q·T = P²/(P + r)) and then follows the blocks,
// λ_i ← λ_i·e^{γ(u_i − 1)} (γ = design::block_match_gain = 0.3), which settles where the block means are as
// the filter predicts them (E u_i = 1); 1 ≤ λ_i ≤ kMaxNoiseRatio². At the detection the attitude's variance
// along d_i grows by m_i − s_i (what the error has already done beyond the model). A failed test of the
// reference with three gyros (which gyro, the data cannot tell) matches every gyro's noise the same way, from
// λ = 1. The gyro is never excluded: three gyros are the rate.

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
  double statistic = 0.0;  //!< [-] the CUSUM g_i at the detection
};

class ReferenceNoiseMatch {
 public:
  ReferenceNoiseMatch(const PipelineConfig& config, int gyro_count);

  //! No gyro detected or matched, the statistics empty (a reset).
  void reset();

  //! One reference sample used by the filter at `now_ns`, before its update: its innovation `z_rad` with
  //! covariance `S`, the rate solution `pinv` (3×N) over exactly three gyros `mask`, the filter (its model's
  //! noise; it receives the matched noise). Returns the gyro detected at this sample, if one is.
  std::optional<NoiseFinding> observe(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                      const Eigen::Matrix3d& S, const Eigen::Matrix3Xd& pinv, GyroMask mask,
                                      Mekf& filter);

  //! A test of the reference failed with three gyros (the data cannot tell which gyro): every gyro of
  //! `mask` has its noise matched from the next sample on.
  void match_all(GyroMask mask);
  //! Gyro `id` reinstated: its filter noise is the model's again (the filter's thaw), and so is its match.
  void forget(int id);
  //! Gyro `id`'s own noise level (own_noise_level.hpp) shows a white noise variance `ratio` (≥ 1) times the
  //! model's: the filter's noise for it is at least that from now on, whatever the innovations say.
  void set_own_ratio(int id, double ratio, Mekf& filter);
  //! Every gyro's white noise variance is `ratio` (≥ 1) times the model's as the parity's own spread shows
  //! it (parity_spread.hpp): the filter's noise for each is at least that from now on.
  void set_common_ratio(double ratio, Mekf& filter);
  //! [rad] 1σ per axis of the reference samples from now on (the configured one, or its re-estimated noise).
  void set_reference_sigma_rad(double sigma_rad) { reference_var_ = sigma_rad * sigma_rad; }

 private:
  void restart_statistics();  //!< the CUSUMs, mean squares and blocks empty; what is matched kept
  //! The filter's noise of gyro index `k`: the larger of the innovations' match and its own level's.
  void apply(std::size_t k, Mekf& filter) const;
  //! [rad²/s] gyro index `i`'s noise beyond the model from its mean square along `d` (|h_i|² = `h2`, sample
  //! interval `T`): the covariance-matching start.
  double mapped_noise(int i, const Eigen::Vector3d& d, double h2, double T, const Eigen::Matrix3Xd& pinv,
                      GyroMask mask, const Mekf& filter) const;

  double false_alarm_ = 0.0;          //!< p per sample
  double window_s_ = 30.0;            //!< [s] the mean square's time constant
  double reference_var_ = 0.0;        //!< [rad²] r, the reference's variance per axis
  GyroMask mask_ = 0;                 //!< the three gyros of the statistics
  std::int64_t last_ns_ = -1;         //!< the last sample's time
  std::int64_t block_start_ns_ = -1;  //!< the CUSUM block's first sample
  int block_samples_ = 0;             //!< samples in the block
  std::vector<double> cusum_;         //!< [-] g_i
  std::vector<double> mean_square_;   //!< [rad²] m_i
  std::vector<double> block_z_;       //!< [rad] Σ d_iᵀz over the block
  std::vector<double> block_s_;       //!< [rad²] Σ s_i over the block
  std::vector<bool> matched_;  //!< per gyro: detected (or a reference test failed), its noise matched since
  std::vector<double>
      ratio_;  //!< [-] the matched noise variance over the model's, N'²/N², 1..kMaxNoiseRatio²
  std::vector<double> own_;  //!< [-] per gyro: the variance ratio its own noise level shows (1: none)
  double common_ = 1.0;      //!< [-] every gyro: the variance ratio the parity's spread shows (1: none)
};

}  // namespace tetra::fdi::detail
