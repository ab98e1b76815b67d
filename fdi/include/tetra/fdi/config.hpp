#pragma once
// Pipeline configuration: a struct with in-class defaults, validated once, echoed at start-up.
// Read from the `pipeline:` map of a YAML file (replay --config, fusion --config).
// Every key is declared once, with its unit, range, default and meaning, in one table
// (fdi/src/config_keys.cpp) that drives parsing, validate(), describe() and describe_keys(); how the
// thresholds follow: docs/fdi.md.

#include <optional>
#include <string>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"

namespace YAML {
class Node;  // yaml-cpp; only callers that hold a parsed node include it
}  // namespace YAML

namespace tetra::fdi {

struct PipelineConfig {
  // --- attitude
  std::optional<double> latitude_deg;                //!< [deg] ground-test mode: remove Earth rate
  Quaternion initial_q_RB = Quaternion::Identity();  //!< initial attitude (relative to L in ground mode)

  // --- input
  bool raw_units_dps = false;    //!< samples are already rates [deg/s] (log "# units=dps"): no s, β applied
  double sample_period_s = 0.0;  //!< [s] nominal sample period; 0 = the first time step seen
  double max_abs_raw_V = 10.0;   //!< [V] a raw sample beyond this is invalid
  double max_abs_rate_dps = 100.0;       //!< [deg/s] a calibrated rate beyond this is invalid
  double default_arw_dps_rtHz = 3.0e-5;  //!< [deg/√s] N of a gyro without `noise:` (seed Table 6)
  //! [deg/s] B of a gyro without `noise:` section: twice the seed's Table 6 level, conservative
  double default_bias_instability_dps = 1.0e-5;

  // --- the error budget (docs/fdi.md, "The budget"; fdi/include/tetra/fdi/budget.hpp)
  //! [-] the unit of the budget: each test's error probability (per epoch or per sample) is its share of
  //! this (χ², jump, GLT, reference tests 1; CUSUM 10; reference gate 1000: kAllocations)
  double false_alarm_probability = 1.0e-9;

  // --- detection on the parity residual
  double cusum_min_fault_dps = 2.0e-4;  //!< [deg/s] smallest bias step on any gyro the CUSUM is sized for
  //! [s] the rate random walk K of a gyro's `noise:` enters the detectors' reference noise as K·√horizon
  double rate_random_walk_horizon_s = 3600.0;
  double clear_after_s = 30.0;  //!< [s] no alarm for this long ends a SUSPECT episode

  // --- isolation
  double max_angular_acceleration_dps2 = 1.0e-3;  //!< [deg/s²] bound on the vehicle's angular acceleration
  double onset_sigma = 5.0;                       //!< [σ] margin of the onset (physical possibility) test
  double dropout_timeout_s = 1.0;                 //!< [s] absent (dropout) or invalid (invalid) this long
  double max_gap_s = 2.0;                         //!< [s] no epoch for longer than this: a `gap` event
  double noise_high_ratio = 4.0;                  //!< [-] robust noise level / expected above this → noise
  //! [s] window of the reference comparison and block of the reference's own tests (docs/fdi.md)
  double reference_window_s = 30.0;
  double reference_sigma_arcsec = 5.0;     //!< [arcsec] 1σ per axis of the attitude reference
  double reference_threshold_sigma = 6.0;  //!< [σ] reference disagreement threshold
  //! false: a gyro isolated as faulty stays in the solution (detection and isolation still run and
  //! report; for experiments that measure what exclusion is worth). The `isolated` event then says
  //! "gyro kept" and detection starts again; replay, the service and the closed-loop simulator alike.
  bool exclusion_enabled = true;
  //! true: during a fault episode with a reference, one gyro's filter bias estimate alone beyond
  //! reference_threshold_sigma isolates it, once a single-gyro fault of that gyro explains the episode's
  //! parity and reference records better than every other gyro's by a margin and persists (docs/fdi.md).
  bool filter_bias_isolation = true;

  // --- attitude filter (docs/fdi.md, "Attitude filter")
  //! [deg] 1σ per axis of `initial_q_wxyz` until a reference sample sets the attitude (0 only if set so).
  double initial_sigma_deg = 0.1;
  //! [s] correlation time T_c of the Gauss–Markov bias that models each gyro's bias instability B.
  double bias_instability_correlation_s = 100.0;

  // --- the reference as a sensor that can fail (docs/fdi.md, "Reference consistency")
  //! [arcsec] 1σ per axis of the reference's slowly varying error its specification states (thermo-elastic
  //! bias, low-spatial-frequency error): the filter follows it unseen, so sigma carries it (0: none stated)
  double reference_bias_arcsec = 0.0;
  //! [s] the largest latency of the reference's time stamps its specification allows: at a steady rate it is
  //! an unseen offset ω·τ, so sigma carries |ω|·this (0: stamps exact)
  double reference_latency_max_s = 0.0;
  //! [s] the fusion horizon: a reference delivered after its epoch was fused and stamped at most this long
  //! before the epoch it reaches is fused at its own time; an older one is left out, counted and reported
  //! (`reference_late`). Covers a star tracker delivering up to 300 ms late, with the service's wait.
  double reference_horizon_s = 0.5;

  // --- integrity (docs/fdi.md, "Protection level")
  //! [-] probability that the attitude error exceeds the published protection level without an alarm
  double integrity_risk = 1.0e-7;

  // --- calibration uncertainty (docs/fdi.md, "Calibration uncertainty")
  //! [-] multiple of the calibration file's stated 1σ (scale factors, axes) the parity tests tolerate: an
  //! error of every scale factor and axis component within this many σ never raises the parity beyond its
  //! noise
  double calibration_error_sigmas = 3.0;
};

//! Fixed design constants: values the detectors are built around that a user has no physical reason to
//! set. Each value is declared here once; its unit and meaning are rows of the same table as the keys
//! (fdi/src/config_keys.cpp, design_constants()), listed by `tetra replay --config-keys` under their own
//! heading and in docs/fdi.md ("Configuration"). A `pipeline:` map that sets one is an error naming the
//! file, the line and the constant.
namespace design {
// --- detection and isolation on the parity residual
inline constexpr double isolation_window_s = 5.0;  //!< [s] evidence sought this long before `unisolated`
inline constexpr int onset_pre_epochs = 20;        //!< [epochs] window before the estimated onset
inline constexpr int onset_post_max_epochs = 50;   //!< [epochs] at most this many epochs after the onset
inline constexpr int onset_min_post_epochs = 20;   //!< [epochs] the onset test judges from this many on
inline constexpr int onset_confirm_epochs = 10;    //!< [epochs] an outlier this persistent is a step
// --- a gyro's own samples
inline constexpr int stuck_repeat_count = 10;         //!< [samples] identical raw values in a row: stuck
inline constexpr int stuck_repeat_isolated = 5;       //!< [samples] repeats that make an isolated fault stuck
inline constexpr int noise_window = 30;               //!< [samples] window of the noise-level tests
inline constexpr double noise_low_ratio = 0.05;       //!< [-] robust noise level / expected below: stuck
inline constexpr double noise_raised_fraction = 0.5;  //!< [-] of noise_high_ratio: a raised noise level
inline constexpr int spike_count = 3;            //!< [-] confirmed outliers within spike_window_s: spikes
inline constexpr double spike_window_s = 120.0;  //!< [s] window of the spike count
// --- the reference
inline constexpr int reference_confirm_count = 3;         //!< [-] consecutive comparisons that must agree
inline constexpr int reference_gate_reset_count = 10;     //!< [samples] gate rejections that set the attitude
inline constexpr double reference_bias_window_s = 120.0;  //!< [s] block of the mean-innovation test
inline constexpr double reference_noise_max_factor = 3.0;  //!< [-] × reference_sigma_arcsec: re-estimate
//! [samples] the step test's window: the onsets it searches (its threshold at p / this many)
inline constexpr int reference_step_samples = 64;
//! [-] the bias test's mean is consistent with a good reference up to χ²₃(1 − this); beyond, until a match
//! or a rejection decides, the protection level carries the reference's pull as a match would
inline constexpr double reference_mean_accept_probability = 1.0e-3;
// --- the noise model checked against the parity's spread
inline constexpr double spread_block_s = 5.0;       //!< [s] blocks of the long-run spread
inline constexpr int spread_window_samples = 3000;  //!< [samples] of one verdict at most
inline constexpr int spread_min_samples = 20;       //!< [samples] of one verdict at least
inline constexpr int spread_hold_samples = 100;     //!< [samples] before the model counts as checked
inline constexpr int spread_hold_epochs = 300;      //!< [epochs] after which it counts as checked anyway
inline constexpr double spread_hold_s = 30.0;       //!< [s] after which it counts as checked anyway
inline constexpr double spread_held_ratio = 16.0;   //!< [-] noise variance ratio an unchecked model may hide
inline constexpr double spread_white_dominates = 0.1;  //!< [-] quantization share: one sample shows the white
//! [σ] the estimate's interval whose upper end it takes
inline constexpr double spread_interval_sigmas = 1.0;
//! [-] variance inflation of a mean of successive differences' u (lag-one correlation 0.25 for white noise,
//! 0.47 for quantization, whose rate error is itself a difference): the likelihood ratio is divided by it
inline constexpr double spread_difference_inflation = 2.0;
// --- the CUSUM's design, the level test and the block matches
//! [bias σ] reach of the design's average over a mean
inline constexpr double cusum_bias_average_reach = 6.0;
//! [-] the averaged CUSUM design is kept unless absorbing the mean detects the design shift more than this
//! many times sooner: the two are within a few per cent for a wander well inside the reach, the average's h
//! grows without bound as the reach passes k
inline constexpr double cusum_average_kept_within = 2.0;
//! [σ of the held level] offset the level test absorbs
inline constexpr double level_margin_sigmas = 3.0;
//! [s] block of the parity block match's mean
inline constexpr double parity_bias_block_s = 30.0;
//! [blocks] quiet blocks in a row that end a match
inline constexpr int parity_bias_quiet_blocks = 10;
//! [-] a block match's alternative: the covariance ×
inline constexpr double block_match_ratio = 4.0;
//! [-] a matched ratio's step per block, e^{γ(u/d − 1)}
inline constexpr double block_match_gain = 0.3;
//! [s] block of the reference matches' mean innovation
inline constexpr double reference_match_block_s = 10.0;
// --- isolation
//! [-] a single-gyro model whose residual exceeds this quantile of its χ² is not accepted (the records hold
//! something no single-gyro fault explains)
inline constexpr double bias_model_reject_probability = 1e-6;
//! [σ²] the best gyro's fit over any other's (5σ)
inline constexpr double bias_hypothesis_margin_sigma2 = 25.0;
//! [σ²] its fit of the latest half-span (4σ)
inline constexpr double bias_hypothesis_persist_sigma2 = 16.0;
//! [σ²] one drift model's fit over the other's (4σ)
inline constexpr double drift_margin_sigma2 = 16.0;
//! [epochs] the drift models judge from this many on
inline constexpr int drift_min_epochs = 20;
//! [σ²] a slope's fit below: no trend (3σ)
inline constexpr double drift_no_trend_sigma2 = 9.0;
//! [epochs] the GLT baseline's longest window
inline constexpr int glt_baseline_max_epochs = 200;
//! [epochs] its shortest
inline constexpr int glt_baseline_min_epochs = 20;
//! [epochs] its blocks for the noise it shows
inline constexpr int glt_noise_block_epochs = 10;
//! [σ] the disagreement trend's prediction margin
inline constexpr double trend_margin_sigmas = 3.0;
// --- a gyro's own samples (continued)
//! [samples] the noise-level test runs this often
inline constexpr int noise_eval_every_samples = 10;
//! [σ] a quantization step beyond: repeats are normal
inline constexpr double coarse_step_per_sigma = 0.1;
//! [σ] motion the noise-level test tells from noise
inline constexpr double quiet_motion_sigmas = 2.0;
//! [-] own second differences that look normal
inline constexpr double motion_quiet_ratio = 2.0;
//! [samples] another gyro's run leaving repeats unjudged
inline constexpr int other_repeats_samples = 3;
//! [-] pieces of a repeat run that one other gyro's fault explains: its level changed at most twice during
//! the run (a step; a spike or a pulse that came and went), so the others' view of the axis may sit at up to
//! three levels while the gyro's own rate stood still
inline constexpr int pieces_one_fault_explains = 3;
//! [values] the own noise level is evaluated this often
inline constexpr int own_noise_eval_every = 10;
//! [evaluations] its ratio's smoothing
inline constexpr double own_noise_smoothing_evaluations = 10.0;
//! [-] a named gyro's smoothed level below: normal
inline constexpr double own_noise_normal_ratio = 1.5;
// --- the data path
//! [s] how long the acceleration the gyros saw is remembered for a lost rate's bound: a slew's acceleration
//! changes over seconds, and a few epochs without a rate are what drops and gaps make
inline constexpr double accel_memory_s = 5.0;
//! [σ] the noise of a seen slope left out before it counts as the body's acceleration: the largest of the
//! three axes' slopes over the memory (about 150 steps at 10 Hz) passes 5σ with probability below 1e-4
inline constexpr double slope_noise_sigmas = 5.0;
//! [sample periods] the stamp judge's window
inline constexpr int stamp_window_periods = 1000;
//! [-] agreeing stamps that confirm a forward jump
inline constexpr int stamp_confirm_count = 3;
// --- the reference (continued)
//! [-] the lone-gyro rule: every other gyro below this fraction of the reference threshold
inline constexpr double lone_gyro_others_fraction = 0.5;
//! [σ] a gyro's disagreement that follows the rotation beyond this many σ of its slope: a scale error
inline constexpr double scale_slope_sigmas = 5.0;
//! [-] of reference_window_s: the shortest span the filter-bias fault-model check fits
inline constexpr double filter_bias_min_span_fraction = 0.5;
//! [-] of reference_window_s: the shortest latest half-span the fault must persist in
inline constexpr double filter_bias_late_span_fraction = 0.25;
//! [-] the largest λ: a mean that needs more (a random walk 100 times the model's own wander in σ) is not a
//! drift of working gyros but the reference's, and is left to its tests (a warm-up of 5e-6 to 8e-5 deg/s over
//! minutes needs up to about 700; a reference's bias of 10–40″ 5e4 in the median)
inline constexpr double reference_max_wander_ratio = 1.0e4;
//! [reference bias windows] the bias match's long window
inline constexpr double reference_long_windows = 4.0;
//! [-] the largest white rate noise the filter takes on, as a multiple of the model's N (a noise ×30 of a
//! fiber-optic gyro is a failed gyro, not a degraded one)
inline constexpr double reference_max_noise_ratio = 30.0;
// --- the calibration's motion fit
//! [s] one block of the motion fit: long enough for a slew or two, short enough to name a mismatch within
//! ten minutes of motion
inline constexpr double motion_fit_block_s = 300.0;
//! [blocks] blocks in a row whose rows make the case before a mismatch is named: a fault's onset inside a
//! block bends that block's fit; the next block shows the fault as the single gyro's it is
inline constexpr int motion_fit_blocks_in_a_row = 2;
//! [epochs] a block with fewer is not judged (a set that changed just before the block's end)
inline constexpr int motion_fit_min_epochs = 10;
}  // namespace design

//! Parses a `pipeline:` YAML map (unknown keys are errors naming the line); `source` names the file.
Result<PipelineConfig> pipeline_config_from_yaml(const YAML::Node& node, const std::string& source);
//! Reads a YAML file whose top level holds a `pipeline:` map (other top-level keys are ignored,
//! so one file can configure the DDS service too).
Result<PipelineConfig> read_pipeline_config(const std::string& path);
//! The same from YAML text (e.g. a Python dict as JSON); `source` names it in messages.
Result<PipelineConfig> parse_pipeline_config(const std::string& yaml_text, const std::string& source);
//! Validates ranges; the error names the key, the range and the value.
Status validate(const PipelineConfig& config);
//! Multi-line "key: value" echo of every key, for start-up logs.
std::string describe(const PipelineConfig& config);
//! Every key as a table, one line each: key, unit, range, default, meaning; then the fixed design
//! constants, one line each: name, unit, value, meaning (tetra replay --config-keys).
std::string describe_keys();
//! A YAML file with a `pipeline:` map of every key at its default, each after a comment with its unit,
//! range and meaning: examples/fusion.yaml (tetra replay --config-example).
std::string example_config();

}  // namespace tetra::fdi
