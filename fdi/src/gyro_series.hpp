#pragma once
// Input validation, calibration and each gyro's own series: the per-gyro signatures of docs/fdi.md
// (invalid, dropout, repeated values, noise level, recurring spikes). A gyro's signature needs only its own
// samples, so it tells which gyro failed by construction.

#include <array>
#include <cstdint>
#include <vector>

#include "epoch_frame.hpp"
#include "subset_cache.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

//! What the calibration says of one gyro, in SI.
struct GyroConstants {
  double scale_V_per_rad_s = 1.0;  //!< [V/(rad/s)] (1 per rad/s·deg when the log is in deg/s)
  double bias_V = 0.0;             //!< [V]
  double arw_rad_rts = 0.0;        //!< [rad/√s] white rate noise N
  double bias_sigma_rad_s = 0.0;   //!< [rad/s] 1σ of the calibrated bias
  double scale_rel_sigma = 0.0;    //!< [-] 1σ relative scale factor error
  Eigen::Vector3d axis_sigma = Eigen::Vector3d::Zero();  //!< [-] 1σ of each axis component
  double bias_instability_rad_s = 0.0;  //!< [rad/s] B of the calibration's noise section (0 if absent)
  double quantization_rad = 0.0;        //!< [rad] angle quantization Q of the noise section (0 if absent)
};

//! Per-gyro constants from the calibration; error names the gyro and field.
Result<std::vector<GyroConstants>> gyro_constants(const Calibration& cal, const PipelineConfig& config);

//! The element of rank k (0-based) of a[0..n) (a is reordered): the value std::nth_element puts at a + k, by
//! a quickselect whose partition has no data-dependent branch (nth_element's mispredicts on nearly every
//! comparison of noise). Every value must be ordered (no NaN).
double select_rank(double* a, int n, int k);

//! The element of rank k (0-based) of a[0..n) lies strictly between `low` and `high`: decided by counting,
//! without ordering or changing a. False when it does not, or when some value is NaN.
bool rank_within(const double* a, int n, int k, double low, double high);

class GyroSeries {
 public:
  GyroSeries(std::vector<GyroConstants> constants, const PipelineConfig& config);

  //! Validates and calibrates the epoch's samples into `frame` (y, raw, valid) and updates each gyro's
  //! series.
  void ingest(const Epoch& epoch, EpochFrame& frame, Counters& counters);
  //! The body motion the other gyros see, for each gyro with a fresh second difference: its projection on
  //! the gyro's axis (rate, and second difference) from the usable gyros without it. The noise-level and
  //! repeated-value tests compare a gyro with what that motion explains.
  void observe_motion(const EpochFrame& frame, SubsetCache& subsets);
  //! The signatures of every gyro not in `excluded`; isolations appended to `out` in gyro order.
  void check(std::int64_t now_ns, GyroMask excluded, double period_s, double sqrt_period, Isolations& out);

  //! A confirmed one-epoch outlier that went away: a spike of gyro `id`.
  void record_spike(int id, std::int64_t now_ns);
  //! Robust noise level / expected over the last `last` second differences (0: the whole window); NaN if too
  //! few. With `motion`, the same of the motion the other gyros see (∞ when they could not see it).
  double noise_ratio(int id, double sqrt_period, int last = 0, bool motion = false) const;
  //! Trimmed RMS noise level / expected over the last `last` second differences (classification at
  //! isolation).
  double recent_noise_ratio(int id, double sqrt_period, int last) const;
  //! [rad/s] 1σ of one sample: white noise N/√T and, with an angle quantization Q, its √2·Q/T.
  double sample_sigma(int id, double sqrt_period) const;
  //! [rad²/s²] variance of the mean of n consecutive samples (`mean_variance`).
  double window_mean_variance(int id, double sqrt_period, int n) const;
  //! [rad²/s²] variance of the difference of two consecutive samples (`sample_difference_variance`).
  double difference_variance(int id, double sqrt_period) const;
  //! True when the quantization step of one sample is not small beside the white noise (> 0.1 σ): repeated
  //! values and a low second-difference level are then what a healthy gyro delivers.
  bool coarse(int id, double sqrt_period) const;
  //! The motion the other gyros saw along gyro `id`'s axis was quiet enough for its noise level to mean noise
  //! (false when they could not see it): over the window (`last` = 0, median) or its last `last` second
  //! differences (trimmed RMS).
  bool motion_quiet(int id, double sqrt_period, int last) const;
  //! Identical raw values in a row of gyro `id`.
  int repeat_count(int id) const { return track(id).repeat_count; }
  bool absent(int id) const { return track(id).absent_since_ns >= 0; }
  bool invalid(int id) const { return track(id).invalid_since_ns >= 0; }
  const GyroConstants& constants(int id) const { return constants_[static_cast<std::size_t>(id - 1)]; }

  //! A reinstated gyro starts its signature evidence afresh.
  void forget_evidence(int id);
  //! After a reconfiguration: the evidence that the gyros' own samples do not carry alone restarts for every
  //! gyro — the motion the others saw (each value was projected through the old set, the removed gyro in it),
  //! a coarse gyro's repeat-run motion range, and the spike counts (each spike was judged against hypotheses
  //! that included the removed gyro). The gyros' own second differences, repeats, dropouts and invalid
  //! samples are kept: no other gyro is in them.
  void restart_evidence();
  //! No epoch for a while (a gap): second differences do not straddle it.
  void bridge_gap() {
    for (auto& t : tracks_) t.consecutive = 0;
  }
  void reset();

 private:
  static constexpr int kSpikeMemory = 64;  //!< spike times kept per gyro
  struct Track {
    std::int64_t absent_since_ns = -1;
    std::int64_t invalid_since_ns = -1;
    bool has_last_raw = false;
    double last_raw = 0.0;
    int repeat_count = 0;
    int consecutive = 0;     //!< valid samples in a row (up to 2)
    double y1 = 0.0;         //!< [rad/s] previous sample
    double y2 = 0.0;         //!< [rad/s] the one before
    double d2_last = 0.0;    //!< [rad/s] signed Δ²y of this epoch
    bool d2_fresh = false;   //!< d2_last belongs to this epoch
    std::vector<double> d2;  //!< ring of |Δ²y| [rad/s], size noise_window
    std::vector<double> m2;  //!< ring of |h·Δ²ω̂| the other gyros see [rad/s] (∞: not seen), aligned with d2
    // A coarse gyro's repeat run: h·ω̂ of the other gyros cut into the fewest consecutive pieces each within
    // `run_width` (extend_run).
    double run_low = 0.0;  //!< [rad/s] range of h·ω̂ of the other gyros in the run's current piece
    double run_high = 0.0;
    double run_sigma = 0.0;  //!< [rad/s] largest 1σ of that projection in the pieces counted
    int run_pieces = 0;      //!< pieces counted
    bool run_seen = false;
    GyroMask view_mask = ~GyroMask{0};  //!< the other gyros of the cached view (none yet)
    double view_period = 0.0;           //!< [√s] the sample period's root it was made for
    bool view_observable = false;
    bool view_coarse = false;       //!< `coarse` at the view's sample period
    std::vector<double> view_coef;  //!< h_i·H*_(others), per gyro (0 outside the others)
    std::vector<int> view_gyros;    //!< the others' indices (0-based, rising); the first view_count are used
    int view_count = 0;
    double view_rate_sigma = 0.0;  //!< [rad/s] 1σ of the projected rate
    double view_d2_sigma = 0.0;    //!< [rad/s] 1σ of the projected second difference
    double motion_sigma = 0.0;  //!< [rad/s] the others' noise on the motion's second difference (last seen)
    int d2_count = 0;
    int d2_head = 0;
    int d2_since_eval = 0;
    std::array<std::int64_t, kSpikeMemory> spike_ns{};
    int spike_n = 0;  //!< total spikes recorded (ring index = n % memory)
  };
  const Track& track(int id) const { return tracks_[static_cast<std::size_t>(id - 1)]; }
  void ingest_sample(Track& t, double raw, double y);
  //! The last `n` second differences of `t` into the scratch buffer.
  double* recent(const std::vector<double>& ring, const Track& t, int n) const;
  //! RMS of the last `n` values of `ring` without their two largest.
  double trimmed_rms(const std::vector<double>& ring, const Track& t, int n) const;
  //! The window's noise ratio (`noise_ratio` over the whole window) is certainly within (low, high): decided
  //! by `rank_within` on the ring, without the median. False when it may not be (then the ratio itself
  //! decides).
  bool noise_ratio_within(const Track& t, int id, double sqrt_period, double low, double high) const;
  //! Second-difference level [rad/s] of white noise (and quantization) that the noise ratios divide by.
  double d2_sigma(int id, double sqrt_period) const;
  //! Gyro `id`'s view through `others` (coefficients and noise), made when not cached; false when they are
  //! not observable.
  bool motion_view(int id, GyroMask others, SubsetCache& subsets);
  bool make_view(int id, GyroMask others, SubsetCache& subsets);
  //! h_i·H*_(others)·v with the cached coefficients of `t` (summed over the others in rising order).
  double project(const Track& t, const double* v) const;
  //! A noise level `r` that the motion the other gyros see cannot explain.
  bool noise_beyond_motion(int id, const Track& t, double r, double sqrt_period) const;
  //! Every other gyro in use has a normal second-difference level, and none has just begun repeating.
  bool others_normal(int id, double sqrt_period) const;
  //! [-] the unit's own noise level: the median of the gyros' levels in use, at least 1 (1 with fewer than
  //! three): each gyro's level is judged against it.
  double unit_level(double sqrt_period) const;
  //! [rad/s] how far the others' view of gyro `id`'s axis (1σ `sigma`) may range while its own rate stands
  //! within a quantization step: two steps and 2·onset_sigma·σ.
  double run_width(int id, double sigma, double sqrt_period) const;
  //! Adds the others' view `rate` [rad/s] of gyro `id`'s axis to its repeat run's pieces.
  void extend_run(int id, Track& t, double rate, double sqrt_period);
  //! Repeated values that the motion the other gyros saw rules out for a healthy (quantized) gyro.
  bool repeats_are_stuck(int id, const Track& t, double sqrt_period) const;
  //! Some signature of `t` may be due this epoch (false: check_one would find nothing and change nothing).
  bool may_signal(const Track& t) const;
  bool check_one(int id, Track& t, std::int64_t now_ns, double period_s, double sqrt_period, Isolations& out);

  std::vector<GyroConstants> constants_;
  const PipelineConfig& config_;
  std::vector<Track> tracks_;
  mutable std::vector<double> scratch_;
  GyroMask excluded_ = 0;       //!< the gyros `check` leaves alone
  std::vector<double> d2_all_;  //!< this epoch's Δ²y of every gyro of `fresh_` [rad/s]
  GyroMask fresh_ = 0;          //!< the gyros with a second difference this epoch
};

}  // namespace tetra::fdi::detail
