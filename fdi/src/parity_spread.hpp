#pragma once
// The parity's own spread (docs/fdi.md, "A unit noisier than its noise: section"): the white noise the
// detectors whiten with is checked against the data, not trusted. Between two consecutive epochs of the same
// gyros, with the body within the motion bound, the jump test's parity difference p_Δ = √T·W_Δ·Δy/√2 is
// N(0, I_d) under the model whatever the body does (V H = 0), so u = |p_Δ|² is χ²_d; a unit whose white noise
// (N and Q) is λ times the modelled variance gives λ·χ²_d. A bias, a wander or a calibration error is nearly
// constant over one sample and does not reach it; a jump beyond the jump test's threshold c is the jump
// test's (left out: the estimate takes the truncation into account).
//
// Over the samples since the last verdict (at most design::spread_window_samples, then the sums start again),
// with λ̂ the mean of min(u, c) per degree of freedom, the generalized likelihood ratio of "λ = 1" is
//
//   G = ½·Σd·(λ̂ − 1 − ln λ̂) / κ,   κ = design::spread_difference_inflation (successive differences share a
//   sample),
//
// rejected when G > ln(design::spread_window_samples/p) (p the budget's kParitySpread share; the window's
// length bounds the looks). Then λ is estimated by maximum likelihood with the samples beyond c censored,
//
//   ℓ(λ) = −½·Σd_below·ln λ − Σu_below/(2λ) + n_beyond·ln S_d(c/λ),
//
// and the model's white noise is multiplied by the upper end of its 1σ interval (at least
// design::spread_min_samples; never below the stated noise), the detectors restart on it, and the sums start
// again: a rise later in the run is followed the same way, a fall too (the model comes back towards the
// stated noise, never below it). Until the first design::spread_hold_samples samples are in (or
// design::spread_hold_epochs epochs or design::spread_hold_s have passed) the model is unchecked: a parity
// alarm that a white noise up to design::spread_held_ratio times the model's could explain decides nothing
// yet (pipeline.cpp); a larger one is decided at once.
//
// What the parity cannot tell: which gyro is noisier. Every gyro's white noise is taken λ times its model (in
// the filter too: sigma carries it); a single gyro's noise fault is the noise-level test's, which judges each
// gyro's own samples against its stated noise and is not rescaled.

#include <cstdint>
#include <optional>
#include <vector>

#include "tetra/fdi/config.hpp"
#include "tetra/fdi/ledger.hpp"

namespace tetra::fdi::detail {

// The spread's constants are fixed design constants (tetra/fdi/config.hpp, namespace design): spread_block_s,
// spread_window_samples, spread_min_samples, spread_hold_samples, spread_hold_epochs, spread_hold_s,
// spread_held_ratio.

//! The model's white noise rejected: the ratio the data show and the one now taken.
struct SpreadFinding {
  double statistic = 0.0;  //!< [-] G at the verdict
  double threshold = 0.0;  //!< [-] ln(design::spread_window_samples/p)
  double estimate = 1.0;   //!< [-] λ̂ relative to the model before
  double ratio = 1.0;      //!< [-] the white noise variance now taken over the stated
  int samples = 0;         //!< samples of the verdict
};

class ParitySpread {
 public:
  //! `false_alarm` is p per look (the budget's kParitySpread share).
  explicit ParitySpread(double false_alarm);

  //! The stated model, unchecked, the sums empty.
  void reset();
  //! The sums empty (the gyro set changed, a gap): the ratio and the check's state kept.
  void restart();
  //! One epoch: `u` the parity difference's χ² at `dof` with its threshold `cap` (NaN: no clean difference
  //! this epoch). A finding when the model's white noise is rejected; the ratio is then the new one.
  //! `offset`: a part of u's expectation the model's noise ratio does not scale (the stated quantization's
  //! in a block difference, BlockDifferences): u ~ ratio·χ²_d + offset; the estimate is then the moment's,
  //! (Σu − Σoffset)/Σd, without a cap.
  std::optional<SpreadFinding> observe(double u, int dof, double cap, std::int64_t now_ns,
                                       double offset = 0.0);
  //! While the model is unchecked, the Hnoise row of an alarm of `statistic` against `threshold` (`chi2`: a
  //! χ², else a sum in σ): the white noise variance ratio that would explain it, consistent up to
  //! design::spread_held_ratio (the arbiter then lets the alarm decide nothing yet). None once checked.
  std::optional<LedgerRow> noise_row(double statistic, double threshold, bool chi2) const;
  //! The Hnoise row of a sum's alarm (`statistic` against `threshold`, in σ) from the sums since the last
  //! verdict (`cap` their censoring): the white noise variance ratio the alarm needs, consistent up to the
  //! upper end of the ratio's interval from the sums (design::spread_held_ratio before two samples, and at
  //! most).
  LedgerRow allowed_row(double statistic, double threshold, double cap) const;

  //! [-] the white noise variance taken, over the stated (≥ 1).
  double ratio() const { return ratio_; }
  //! [-] the white noise variance the data show, over the stated: below ratio() once a verdict found the
  //! model larger than the data (the upper end of that verdict's 1σ interval), else ratio(). The model is
  //! never taken below the stated noise (a detector whitened with it stays within its budget); a test that
  //! looks for an excess beyond the white noise (the parity block match) judges against this one, which an
  //! overstated white noise would otherwise hide.
  double measured() const { return measured_; }
  //! Another test showed at least `ratio`: taken if larger, the sums empty (they were on the model before).
  void raise_to(double ratio) {
    if (ratio > ratio_) ratio_ = measured_ = ratio;
    clear_sums();
  }
  //! The model has been checked since the last reset.
  bool checked() const { return checked_; }

 private:
  //! [-] the censored maximum-likelihood λ of the sums at the cap `cap` (relative to the current model).
  double estimate(double cap) const;
  //! [-] the upper end of λ's one-sided interval at design::spread_interval_sigmas from the sums.
  double upper(double cap) const;
  //! [-] the 1σ half-width of `estimate` from the sums.
  double interval(double estimate) const;
  void clear_sums();

  double threshold_ = 0.0;
  double ratio_ = 1.0;
  double measured_ = 1.0;  //!< [-] measured(): ≤ ratio_
  bool checked_ = false;
  std::int64_t start_ns_ = -1;  //!< [ns] the first epoch after the reset
  int epochs_ = 0;              //!< epochs since the reset (up to design::spread_hold_epochs)
  int samples_ = 0;             //!< samples in the sums
  int beyond_ = 0;              //!< of them beyond the cap
  int checked_samples_ = 0;     //!< samples since the reset (up to design::spread_hold_samples)
  int dof_ = 1;                 //!< the last sample's
  double sum_capped_ = 0.0;     //!< Σ min(u, c)
  double sum_d_ = 0.0;          //!< Σd of every sample
  double sum_below_ = 0.0;      //!< Σu of the samples below the cap
  double sum_d_below_ = 0.0;    //!< Σd of those
  double sum_offset_ = 0.0;     //!< Σ offset
};

//! The long-run white noise (what every sum sees; the quantization telescopes): the normalized parity summed
//! over blocks of m epochs, and the second difference Δ² of three consecutive blocks' sums, u = |Δ²|²/(6m) ~
//! λ_N·χ²_d + q (q the stated quantization's share, SubsetCache::block_quantization; a slowly varying mean
//! and a ramp cancel, a step shows in two values, which the cap censors). A block counts when every epoch of
//! it had the same gyros as the epoch before (OutlierGate::consecutive) outside a fault episode.
class BlockDifferences {
 public:
  explicit BlockDifferences(int max_dof)
      : sum_(static_cast<std::size_t>(max_dof), 0.0),
        last_(static_cast<std::size_t>(max_dof), 0.0),
        before_(static_cast<std::size_t>(max_dof), 0.0) {}
  void restart() {
    epochs_ = 0;
    blocks_ = 0;
  }
  //! One epoch's parity `p` (dof values) of gyro set `mask`, `clean` when it was a clean spread sample. True
  //! when a block closed with two blocks before it: then u() is the three's statistic.
  bool add(const double* p, int dof, std::uint32_t mask, bool clean, int block_epochs);
  double u() const { return u_; }

 private:
  std::vector<double> sum_;     //!< the block being summed
  std::vector<double> last_;    //!< the block before it
  std::vector<double> before_;  //!< and the one before that
  int epochs_ = 0;
  int blocks_ = 0;  //!< closed blocks in a row (up to 2 kept)
  int dof_ = 0;
  std::uint32_t mask_ = 0;
  double u_ = 0.0;
};

}  // namespace tetra::fdi::detail
