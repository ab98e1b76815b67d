#pragma once
// Three gyros, no parity (docs/fdi.md, "Three gyros: a gyro's own noise level"): a gyro whose white noise
// rises shows it in its own samples, within seconds. With four gyros or more the noise-level test of
// gyro_series tells a gyro's noise from the body's motion by what the other gyros see along its axis; with
// three, no other gyro sees that axis, so the level is taken where motion does not reach: the fourth
// difference
//
//   Δ⁴y_k = y_k − 4y_{k−1} + 6y_{k−2} − 4y_{k−3} + y_{k−4}
//
// (on the stamped times: the fourth divided difference over the five epochs, scaled by 4!·T̄⁴ and normalized
// to Σa² = 70 — the same weights on an even grid, and zero for a cubic in time however the samples fall)
// passes white rate noise with variance 70·N²/T (and an angle quantization Q, whose rate error is
// (e_k − e_{k−1})/T, with 252·Q²/T²), while a motion of time scale τ ≫ T is attenuated by about (2πT/τ)⁴: a
// 45° slew in 10 s (4.5 deg/s at 0.1 Hz) sampled at 10 Hz leaves 7e-5 deg/s, 9 % of the white level of a
// 3e-5 deg/√s gyro. A kink in the rate
// (an acceleration switched on or off) leaves three nonzero values, a step five: the level is the median of
// |Δ⁴y| over noise_window values, which a few of them cannot move. The level r is that median over white
// noise's, 0.6745·σ_Δ⁴. Successive Δ⁴ values are correlated (−0.8 at lag 1), so a window of 30 holds fewer
// independent values than 30: over 2e6 evaluations of white noise (one every 10 values) r exceeded 2 in
// 2.7e-3 of them, 2.5 in 5e-5, 3 in 1e-6, a decade per 0.3; at noise_high_ratio (4) about 3e-10, one naming
// of a healthy gyro in some 300,000 h of three gyros at 10 Hz.
//
// Beyond that limit the gyro is named (an event, never an exclusion: three gyros are the rate) and from
// then on its white noise in the filter is matched to the level: the variance ratio λ = 1 + (r² − 1)·σ²_Δ⁴ /
// (70·N²/T) (the whole excess read as white noise), smoothed over design::own_noise_smoothing_evaluations
// evaluations (so that a window that happens to be low does not shrink sigma) and never below the last
// window's (so that a rise counts at once). A named gyro's level is followed whatever the set (with parity
// back, the noise-level test of gyro_series judges it); it is named no more once the smoothed λ is back below
// λ(kNormalLevel), and then matched no more. An epoch farther than half a sample period from the next
// expected one (a dropped epoch) or a gap breaks every series: a difference across a missing sample would
// carry the body's acceleration.

#include <cstdint>
#include <vector>

#include "epoch_frame.hpp"
#include "gyro_series.hpp"

namespace tetra::fdi::detail {

//! A gyro named by its own noise level at this epoch.
struct OwnNoiseFinding {
  int gyro = 0;        //!< 1..N
  double level = 0.0;  //!< [-] r: median |Δ⁴y| over its white-noise median
  double ratio = 1.0;  //!< [-] λ: the white noise variance matched, over the model's
};

class OwnNoiseLevel {
 public:
  //! Every value of `constants` (N, Q per gyro) and `config` (noise_window, noise_high_ratio) is kept.
  OwnNoiseLevel(const std::vector<GyroConstants>& constants, const PipelineConfig& config);

  //! No gyro named, every series empty.
  void reset();
  //! Gyro `id` reinstated (or its evidence restarted): named no more, its series empty.
  void forget(int id);
  //! No epoch for a while: the differences do not straddle the gap.
  void bridge_gap();
  //! Each valid sample of `frame` extends its gyro's series; an absent or invalid one breaks it, and so does
  //! an epoch `frame.dt_s` farther than half of `period_s` from it (0: not yet known) for every gyro.
  void ingest(const EpochFrame& frame, double period_s);
  //! The gyros due for an evaluation at the sample period √T = `sqrt_period`: those of `candidates` (three,
  //! without parity) may be named, every named one is followed. The gyros named at this epoch are appended to
  //! `named` (cleared first); `ratio` is then current. True when a gyro's ratio changed.
  bool evaluate(GyroMask candidates, double sqrt_period, std::vector<OwnNoiseFinding>& named);
  //! [-] λ of gyro `id`: its matched white noise variance over the model's (1 while not named).
  double ratio(int id) const { return tracks_[static_cast<std::size_t>(id - 1)].ratio; }
  bool named(int id) const { return tracks_[static_cast<std::size_t>(id - 1)].named; }
  //! [-] r of gyro `id` over the whole window; NaN until the window is full.
  double level(int id, double sqrt_period) const;

 private:
  struct Track {
    std::vector<double> d4;              //!< ring of |Δ⁴y| [rad/s], size noise_window
    double y[4] = {0.0, 0.0, 0.0, 0.0};  //!< [rad/s] the last four samples, newest first
    int consecutive = 0;                 //!< valid samples in a row (up to 4)
    int count = 0;                       //!< values in the ring (up to noise_window)
    int head = 0;                        //!< next slot of the ring
    int since_eval = 0;                  //!< values since the last evaluation
    bool named = false;
    double ratio = 1.0;     //!< [-] λ matched
    double smoothed = 1.0;  //!< [-] λ smoothed over the evaluations since naming
  };
  //! [rad/s] 1σ of Δ⁴y of gyro `id`'s white noise and quantization at √T = `sqrt_period`.
  double d4_sigma(int id, double sqrt_period) const;
  //! [-] the white noise variance ratio that level `r` shows (≥ 1).
  double white_ratio(int id, double r, double sqrt_period) const;
  //! Follows named gyro `id` (track `t`) at level `r`; false when it is named no more.
  bool follow(Track& t, int id, double r, double sqrt_period) const;
  //! The last five epochs' times with `now_ns`, and the fourth difference's weights over them.
  void difference_weights(std::int64_t now_ns);
  static void clear(Track& t);       //!< the series empty, named no more
  static void clear_name(Track& t);  //!< named no more, the model's noise

  std::vector<GyroConstants> constants_;
  int window_ = 30;
  double high_ratio_ = 4.0;
  std::vector<Track> tracks_;
  std::int64_t times_ns_[5] = {0, 0, 0, 0, 0};       //!< [ns] the last five epochs, newest first
  int epochs_ = 0;                                   //!< epochs in times_ns_ (up to 5)
  std::int64_t steps_ns_[4] = {0, 0, 0, 0};          //!< [ns] their spacings when weights_ were made
  double weights_[5] = {1.0, -4.0, 6.0, -4.0, 1.0};  //!< Δ⁴'s weights over them, newest first
  mutable std::vector<double> scratch_;
};

}  // namespace tetra::fdi::detail
