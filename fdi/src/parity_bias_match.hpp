#pragma once
// A slow error below the detectors (docs/fdi.md, "A slow error below the detectors"): a gyro whose rate error
// is too small for the CUSUM (sized for cusum_min_fault_dps) yet larger and faster than its bias model — a
// scale change seen only through the attitude control's wobble, a small wandering bias — moves the parity
// all the same, and averaging shows it. Per gyro i of the active set, the filter's parity innovations
// ν = p − √T·W·(ĉ + ĝ) are projected on the gyro's parity column w_i and summed over blocks of
// design::parity_bias_block_s (30 s): the block's mean rate error on the gyro, f̂_i = Σ w_iᵀν / Σ |w_i|², has
// the variance 1/Σ|w_i|² + v_i/n while the filter's model holds (white parity noise; v_i the filter's own
// uncertainty of the biases seen the same way, n the block's epochs: the innovations of a filter whose model
// holds are white, so v_i enters each epoch's innovation afresh, not the block's mean as a whole), so u_i =
// f̂_i²/(1/Σ|w_i|² + v_i/n) is χ²₁. A CUSUM per gyro of
// the log-likelihood ratio for a block variance ρ = 4 times the predicted,
//
//   g_i ← max(0, g_i + ½·((1 − 1/ρ)·u_i − ln ρ));   matched when some g_i > ln(1/(p·n·|S|))
//
// (p = the budget's kParityBlockMatch share per epoch, n the block's epochs, |S| the gyros: by Wald's bound
// the mean run length of each gyro's CUSUM without such an error is at least 1/(p·n·|S|) blocks, of the first
// of the |S| at least about 1/(p·n·|S|²)). The parity columns of different gyros are not orthogonal, so a
// block does not always tell which gyro it is: once matched, every gyro's slow bias is a Gauss–Markov process
// whose stationary variance carries, beyond the model's σ_GM², the excess its own hypothesis gives, F_i² =
// f̂_i² − (1/Σ|w_i|² + v_i/n) (the largest of the blocks since) — sigma covers each single-gyro explanation,
// and the filter follows the error through the parity (and the reference). Nothing is excluded; the first
// block of a match is a noise_model event (row parity_block_match: the crossing CUSUM against its threshold),
// the bias model then follows the data without further events. Blocks run on the epochs whose parity is over
// the whole active set, outside fault episodes (a fault the detectors see is theirs to judge), once the
// reference has been seen (before it the filter estimates no bias, and the biases' own wander, slower than a
// block, would make successive blocks correlated). The random-walk bias also opens, by the largest excess of
// a block-to-block change over both blocks' predicted variances, per second of block. The match ends — every
// model the calibration's again — at an exclusion, or after design::parity_bias_quiet_blocks (10) blocks in a
// row with every CUSUM at 0; the bias states' prior spread (the filter-bias test's) keeps the model's K.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "subset_cache.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

class Mekf;

//! A match begun at this block: the gyro whose CUSUM is furthest beyond the threshold (with one parity row
//! every gyro's u is the same, and the lowest id is named).
struct BlockFinding {
  int gyro = 0;            //!< 1..N
  double statistic = 0.0;  //!< [-] its CUSUM g_i (a log-likelihood ratio)
  double threshold = 0.0;  //!< [-] ln(1/(p·n·|S|))
  double ratio = 0.0;      //!< [-] the block's u_i: its mean's square over the variance the model predicts
};

class ParityBiasMatch {
 public:
  ParityBiasMatch(const PipelineConfig& config, int gyro_count);

  //! Nothing matched, the statistics empty (a reset).
  void reset();
  //! The statistics empty; what is matched kept (an episode opened: its fault is the detectors' to judge).
  void restart();
  //! One epoch's normalized parity `p` over the active set's subset `s` (no episode open), before the
  //! filter's parity update. At a block's end a gyro whose mean rate error exceeds the model has its slow
  //! bias opened in `filter` (Mekf::open_bias_model); the block that begins a match returns its finding.
  std::optional<BlockFinding> observe(std::int64_t now_ns, const Subset& s, const Eigen::VectorXd& p,
                                      double sqrt_period, Mekf& filter);
  //! [-] the white noise variance the data show over the model's (≤ 1; ParitySpread::measured): a block's
  //! white part is predicted with it, so a white noise stated larger than the unit's hides no bias wander.
  void set_white_ratio(double ratio) { white_ratio_ = ratio; }
  //! Gyro `id` reinstated: its match forgotten (the filter's thaw restores its bias model).
  void forget(int id);
  //! Nothing matched any more: every gyro's bias model in `filter` is the calibration's again and the blocks
  //! judge afresh — after an exclusion (the error that matched may have been the excluded gyro's), or after
  //! design::parity_bias_quiet_blocks blocks in which no gyro's CUSUM was above 0.
  void release(Mekf& filter);

 private:
  std::optional<BlockFinding> close_block(const Subset& s, double block_s, Mekf& filter);

  double false_alarm_ = 0.0;          //!< p per epoch
  double white_ratio_ = 1.0;          //!< [-] set_white_ratio()
  GyroMask mask_ = 0;                 //!< the gyros of the statistics
  std::int64_t block_start_ns_ = -1;  //!< the block's first epoch
  int block_epochs_ = 0;
  std::vector<double> sum_wnu_;  //!< [1/(rad/s)] Σ w_iᵀν over the block
  std::vector<double> sum_w2_;   //!< [1/(rad/s)²] Σ |w_i|² over the block
  std::vector<double> cusum_;    //!< [-] g_i
  bool matched_ = false;         //!< a gyro's CUSUM crossed: every gyro's slow bias follows the blocks
  int quiet_blocks_ = 0;         //!< matched: blocks in a row with every CUSUM at 0
  std::vector<double> excess_;   //!< [rad²/s²] F_i², the largest excess so far under gyro i's hypothesis
  std::vector<double> block_excess_;  //!< [rad²/s²] the last block's f̂_i² less its predicted variance
  std::vector<double> walk_;       //!< [rad²/s³] the largest excess of a block-to-block change per second
  std::vector<double> last_f_;     //!< [rad/s] the previous block's f̂_i
  std::vector<double> last_var_;   //!< [rad²/s²] its predicted variance (0: no previous block)
  std::vector<double> block_f_;    //!< [rad/s] this block's f̂_i (scratch)
  std::vector<double> block_var_;  //!< [rad²/s²] its predicted variance (scratch)
  Eigen::VectorXd innovation_;     //!< ν (scratch, sized for N − 3 rows)
  Eigen::VectorXd projection_;     //!< per gyro: √T·W column's response along w_i / |w_i|² (scratch)
};

}  // namespace tetra::fdi::detail
