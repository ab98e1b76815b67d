#include "config_keys.hpp"

#include <cmath>
#include <iterator>

#include "tetra/core/csv.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi {

// Names of this file alone (the library is built in unity batches).
namespace key_table {

using Edge = ConfigLimit::Edge;
using C = PipelineConfig;

constexpr ConfigLimit kFree{};
constexpr ConfigLimit above(double v) {
  return {Edge::kOpen, v};
}
constexpr ConfigLimit from(double v) {
  return {Edge::kClosed, v};
}
constexpr ConfigLimit below(double v) {
  return {Edge::kOpen, v};
}
constexpr ConfigLimit to(double v) {
  return {Edge::kClosed, v};
}

std::string number_text(double v) {
  std::string out;
  append_double(out, v);
  return out;
}

// One row per key. A per-epoch false-alarm probability is in (0, 0.5): a test at 0.5 or more is no test.
// Rules one row cannot state are in validate() (config.cpp), after the rows.
constexpr ConfigKey kKeys[] = {
    // --- attitude
    {"latitude_deg", &C::latitude_deg, "deg", from(-90), to(90),
     "ground-test mode: remove the Earth rate at this latitude (the replay command's own latitude "
     "option overrides it); none: orbit"},
    {"initial_q_wxyz", &C::initial_q_RB, "-", kFree, kFree,
     "initial attitude body -> reference [w, x, y, z] (the lab frame in ground mode)"},
    // --- input
    {"raw_units_dps", &C::raw_units_dps, "-", kFree, kFree,
     "samples are already rates in deg/s: no scale factor or bias applied (replay sets it from "
     "\"# units=dps\")"},
    {"sample_period_s", &C::sample_period_s, "s", from(0), kFree,
     "nominal sample period; 0 = the first time step seen"},
    {"max_abs_raw_V", &C::max_abs_raw_V, "V", above(0), kFree, "a raw sample beyond this is invalid"},
    {"max_abs_rate_dps", &C::max_abs_rate_dps, "deg/s", above(0), kFree,
     "a calibrated rate beyond this is invalid"},
    {"default_arw_dps_rtHz", &C::default_arw_dps_rtHz, "deg/√s", above(0), kFree,
     "angle random walk N of a gyro whose calibration has no noise: section (seed Table 6)"},
    {"default_bias_instability_dps", &C::default_bias_instability_dps, "deg/s", from(0), kFree,
     "bias instability B of a gyro without noise: section: twice the seed's Table 6 level, conservative"},
    // --- the error budget
    {"false_alarm_probability", &C::false_alarm_probability, "-", above(0), below(0.5 / kLargestShare),
     "the budget's unit: each test's error probability per epoch or sample is its share of this (chi2, "
     "jump, GLT, each reference test, reference noise match 1; CUSUM 10, i.e. ARL0 = 1/(10 p); reference "
     "gate, bias matches, motion fit, parity spread 1000: they decide nothing; the verbose replay prints "
     "the budget)"},
    // --- detection on the parity residual
    {"cusum_min_fault_dps", &C::cusum_min_fault_dps, "deg/s", above(0), kFree,
     "smallest bias step on any gyro the CUSUM is sized for (k = delta_min/2); also the parity block "
     "match's lower end"},
    {"rate_random_walk_horizon_s", &C::rate_random_walk_horizon_s, "s", above(0), kFree,
     "the horizon H of a gyro's rate random walk K and rate ramp R where they are bounded, not tracked: "
     "1 sigma K*sqrt(H) (the average's reach, the tracker's prior) and R*H on a subset missing a sample"},
    {"clear_after_s", &C::clear_after_s, "s", above(0), kFree,
     "no alarm for this long ends a SUSPECT episode (cleared)"},
    // --- isolation
    {"max_angular_acceleration_dps2", &C::max_angular_acceleration_dps2, "deg/s²", above(0), kFree,
     "bound on the vehicle's angular acceleration: the onset and jump tests, and the widening of sigma "
     "over a gap"},
    {"onset_sigma", &C::onset_sigma, "σ", above(0), kFree,
     "noise margin of the onset (physical possibility) test; also of the jump test and of the repeated-"
     "value (stuck) signature"},
    {"dropout_timeout_s", &C::dropout_timeout_s, "s", above(0), kFree,
     "absent this long: dropout; invalid this long: invalid"},
    {"max_gap_s", &C::max_gap_s, "s", above(0), kFree,
     "no epoch for longer than this: a gap event, sigma widened by a*tau^2/4"},
    {"noise_high_ratio", &C::noise_high_ratio, "-", above(1), kFree,
     "robust noise level / expected above this: noise; also the three-gyro own-noise match, the outlier "
     "gate's and the isolator's noise waits (at noise_raised_fraction of it)"},
    // --- the reference
    {"reference_window_s", &C::reference_window_s, "s", above(0), kFree,
     "window of the reference comparison and how long a reference sample counts as recent (absent beyond "
     "it); also the block of the reference's NIS and lag tests: a rejected reference is used again after "
     "its samples passed every test this long, its noise re-estimate, the three-gyro reference noise "
     "match, the budget's hold, a rejection withdrawn at a detection, sigma after the reference set the "
     "attitude, the bias opened with three gyros"},
    {"reference_sigma_arcsec", &C::reference_sigma_arcsec, "arcsec", above(0), kFree,
     "1σ per axis of the attitude reference (filter, reference comparison, consistency tests)"},
    {"reference_threshold_sigma", &C::reference_threshold_sigma, "σ", above(0), kFree,
     "reference disagreement threshold; also the filter-bias isolation's"},
    {"exclusion_enabled", &C::exclusion_enabled, "-", kFree, kFree,
     "false: an isolated gyro stays in the solution (the isolated event says \"gyro kept\"; for measuring "
     "what exclusion is worth)"},
    {"filter_bias_isolation", &C::filter_bias_isolation, "-", kFree, kFree,
     "with a reference, during a fault episode, a gyro whose filter bias estimate alone is beyond "
     "reference_threshold_sigma is isolated once one fault of it explains the episode best; false: "
     "published only"},
    // --- attitude filter
    {"initial_sigma_deg", &C::initial_sigma_deg, "deg", from(0), to(180),
     "1σ per axis of initial_q_wxyz until a reference sample sets the attitude"},
    {"bias_instability_correlation_s", &C::bias_instability_correlation_s, "s", above(0), kFree,
     "correlation time T_c of the Gauss-Markov bias that models each gyro's bias instability B"},
    // --- the reference as a sensor that can fail
    {"reference_bias_arcsec", &C::reference_bias_arcsec, "arcsec", from(0), kFree,
     "1σ per axis of the reference's slowly varying error its specification states, carried in sigma "
     "(0: none stated)"},
    {"reference_latency_max_s", &C::reference_latency_max_s, "s", from(0), to(10),
     "largest latency of the reference's stamps its specification allows: sigma carries |ω|*this "
     "(0: exact)"},
    {"reference_horizon_s", &C::reference_horizon_s, "s", from(0), to(10),
     "fusion horizon: a reference stamped up to this long before the epoch it reaches is fused at its "
     "own time; older: left out and reported (reference_late)"},
    // --- integrity, calibration uncertainty
    {"integrity_risk", &C::integrity_risk, "-", above(0), below(0.5),
     "probability that the attitude error exceeds the protection level without an alarm"},
    {"calibration_error_sigmas", &C::calibration_error_sigmas, "-", from(0), to(100),
     "errors of the biases, scale factors and axes within this many of the calibration's stated 1σ never "
     "reach the parity tests nor the reference comparison (0: off)"},
};

// One row per fixed design constant: its value is design::'s (config.hpp), its name the same.
constexpr DesignConstant kConstants[] = {
    // --- detection and isolation on the parity residual
    {"isolation_window_s", design::isolation_window_s, "s",
     "evidence is sought this long before unisolated; also the span of the held parity level and the "
     "budget's GLT and reference-window evaluations"},
    {"onset_pre_epochs", design::onset_pre_epochs, "epochs", "window before the estimated onset"},
    {"onset_post_max_epochs", design::onset_post_max_epochs, "epochs",
     "at most this many epochs after the onset (the budget counts the onset test's evaluations up to it)"},
    {"onset_min_post_epochs", design::onset_min_post_epochs, "epochs",
     "the onset test judges once this many epochs follow the onset"},
    {"onset_confirm_epochs", design::onset_confirm_epochs, "epochs",
     "an outlier this persistent is a step, not a spike; also the span of the outlier gate's noise and "
     "motion waits"},
    // --- a gyro's own samples
    {"stuck_repeat_count", design::stuck_repeat_count, "samples", "identical raw values in a row: stuck"},
    {"stuck_repeat_isolated", design::stuck_repeat_isolated, "samples",
     "identical raw values in a row that make an isolated fault's kind stuck, whatever the onset estimate"},
    {"noise_window", design::noise_window, "samples",
     "window of the noise-level (second difference) test and of the own fourth-difference level"},
    {"noise_low_ratio", design::noise_low_ratio, "-", "robust noise level / expected below this: stuck"},
    {"noise_raised_fraction", design::noise_raised_fraction, "-",
     "a noise level above this fraction of noise_high_ratio is raised: the isolator waits or names noise; "
     "recurring spikes are named only below it"},
    {"spike_count", design::spike_count, "-",
     "this many confirmed one-epoch outliers within spike_window_s: recurring spikes"},
    {"spike_window_s", design::spike_window_s, "s", "window of the spike count"},
    // --- the reference
    {"reference_confirm_count", design::reference_confirm_count, "-",
     "consecutive reference comparisons (and filter bias samples) that must agree"},
    {"reference_gate_reset_count", design::reference_gate_reset_count, "samples",
     "the last of this many reference samples in a row the gate would reject sets the attitude"},
    {"reference_bias_window_s", design::reference_bias_window_s, "s",
     "block of the reference's mean-innovation (bias) test"},
    {"reference_noise_max_factor", design::reference_noise_max_factor, "-",
     "a reference rejected for nis alone is used again with its re-estimated noise up to this times "
     "reference_sigma_arcsec"},
    {"reference_step_samples", design::reference_step_samples, "samples",
     "the reference step test's window: the onsets it searches, its threshold at p over this many"},
    {"reference_mean_accept_probability", design::reference_mean_accept_probability, "-",
     "the bias test's mean is consistent up to chi2_3(1 - this); beyond, the protection level carries the "
     "reference's pull until a match or a rejection decides"},
    // --- the noise model checked against the parity's spread
    {"spread_block_s", design::spread_block_s, "s",
     "blocks of the long-run spread (second differences of their parity sums)"},
    {"spread_window_samples", design::spread_window_samples, "samples",
     "samples of one spread verdict at most; then its sums start again (the looks the threshold counts)"},
    {"spread_min_samples", design::spread_min_samples, "samples", "samples of one spread verdict at least"},
    {"spread_hold_samples", design::spread_hold_samples, "samples",
     "one-sample spread samples after a reset before the noise model counts as checked"},
    {"spread_hold_epochs", design::spread_hold_epochs, "epochs",
     "epochs after a reset after which the noise model counts as checked without samples"},
    {"spread_hold_s", design::spread_hold_s, "s", "time after a reset after which it counts as checked"},
    {"spread_held_ratio", design::spread_held_ratio, "-",
     "the white noise variance ratio an unchecked model may hide: an alarm within it (a chi2 up to this "
     "times its threshold, a sum up to its root times) decides nothing before the check"},
    {"spread_white_dominates", design::spread_white_dominates, "-",
     "a unit whose stated quantization is at most this share of one sample's noise: one sample's spread "
     "is the white noise's (the long-run spread is not waited for)"},
    {"spread_interval_sigmas", design::spread_interval_sigmas, "σ",
     "the long-run spread's estimate is taken at the upper end of its interval of this many σ"},
    {"spread_difference_inflation", design::spread_difference_inflation, "-",
     "variance inflation of a mean of successive differences' statistic (lag-one correlation 0.25 for "
     "white "
     "noise, 0.47 for quantization): the spread's likelihood ratio is divided by it"},
    // --- the CUSUM's design, the level test and the block matches
    {"cusum_bias_average_reach", design::cusum_bias_average_reach, "σ",
     "the CUSUM's ARL0 is averaged over a quasi-static parity mean out to this many of its σ"},
    {"cusum_average_kept_within", design::cusum_average_kept_within, "-",
     "the averaged CUSUM design is kept unless absorbing the mean detects the design shift more than this "
     "many times sooner"},
    {"level_margin_sigmas", design::level_margin_sigmas, "σ",
     "offset of the held level the level test's k absorbs"},
    {"parity_bias_block_s", design::parity_bias_block_s, "s",
     "block of the parity block match's mean innovation"},
    {"parity_bias_quiet_blocks", design::parity_bias_quiet_blocks, "blocks",
     "blocks in a row with every CUSUM at 0 that end a parity block match"},
    {"block_match_ratio", design::block_match_ratio, "-",
     "the block matches' alternative: the block's covariance times this"},
    {"block_match_gain", design::block_match_gain, "-",
     "a matched noise ratio's step per block, times e^(gain (u/d - 1))"},
    {"reference_match_block_s", design::reference_match_block_s, "s",
     "block of the reference matches' mean innovation"},
    // --- isolation
    {"bias_model_reject_probability", design::bias_model_reject_probability, "-",
     "a single-gyro fit of the filter-bias records whose residual exceeds this quantile of its chi2 is not "
     "accepted (no single-gyro fault explains them)"},
    {"bias_hypothesis_margin_sigma2", design::bias_hypothesis_margin_sigma2, "σ²",
     "how much more of the records the best gyro's fault must explain than any other's (5σ)"},
    {"bias_hypothesis_persist_sigma2", design::bias_hypothesis_persist_sigma2, "σ²",
     "how much of the latest half-span's records the gyro's fault must explain (4σ)"},
    {"drift_margin_sigma2", design::drift_margin_sigma2, "σ²",
     "how much more of the parity one drift model (step, ramp) must explain than the other to name the "
     "kind "
     "(4σ)"},
    {"drift_min_epochs", design::drift_min_epochs, "epochs",
     "epochs of the history the drift models (step, ramp) need to name a kind"},
    {"drift_no_trend_sigma2", design::drift_no_trend_sigma2, "σ²",
     "a slope whose fit is below this is no trend: an offset through the whole history is a bias (3σ)"},
    {"glt_baseline_max_epochs", design::glt_baseline_max_epochs, "epochs",
     "longest window of the GLT's pre-onset baseline"},
    {"glt_baseline_min_epochs", design::glt_baseline_min_epochs, "epochs",
     "shortest window of the GLT's baseline: fewer clean epochs, no baseline"},
    {"glt_noise_block_epochs", design::glt_noise_block_epochs, "epochs",
     "blocks of the GLT baseline whose means show its noise"},
    {"trend_margin_sigmas", design::trend_margin_sigmas, "σ",
     "margin of the reference disagreement trend's prediction"},
    // --- a gyro's own samples (continued)
    {"noise_eval_every_samples", design::noise_eval_every_samples, "samples",
     "the noise-level test is evaluated this often"},
    {"coarse_step_per_sigma", design::coarse_step_per_sigma, "σ",
     "a quantization step beyond this many σ of one sample's noise makes repeated values normal"},
    {"quiet_motion_sigmas", design::quiet_motion_sigmas, "σ",
     "motion level, in the others' noise, the noise-level test still tells from noise"},
    {"motion_quiet_ratio", design::motion_quiet_ratio, "-",
     "noise ratio of a gyro whose own second differences look normal"},
    {"other_repeats_samples", design::other_repeats_samples, "samples",
     "another gyro's repeat run this long leaves a coarse gyro's repeats unjudged"},
    {"pieces_one_fault_explains", design::pieces_one_fault_explains, "-",
     "levels of the others' view during a repeat run that one other gyro's fault explains (a step, a "
     "spike)"},
    {"own_noise_eval_every", design::own_noise_eval_every, "values",
     "the own noise level is evaluated this often"},
    {"own_noise_smoothing_evaluations", design::own_noise_smoothing_evaluations, "evaluations",
     "smoothing of the own noise level's ratio"},
    {"own_noise_normal_ratio", design::own_noise_normal_ratio, "-",
     "a named gyro's smoothed own noise ratio back below this: normal"},
    // --- the data path
    {"accel_memory_s", design::accel_memory_s, "s",
     "the acceleration the gyros saw is remembered this long for a lost rate's bound"},
    {"slope_noise_sigmas", design::slope_noise_sigmas, "σ",
     "a seen slope's noise left out before it counts as the body's acceleration"},
    {"stamp_window_periods", design::stamp_window_periods, "periods", "the stamp judge's window"},
    {"stamp_confirm_count", design::stamp_confirm_count, "-", "agreeing stamps that confirm a forward jump"},
    // --- the reference (continued)
    {"lone_gyro_others_fraction", design::lone_gyro_others_fraction, "-",
     "the reference comparison's lone-gyro rule: one gyro beyond the threshold, every other below this "
     "fraction of it (the reference's hypothesis rejected only then)"},
    {"scale_slope_sigmas", design::scale_slope_sigmas, "σ",
     "a gyro's disagreement with the reference whose slope against the rotation is beyond this many σ is a "
     "scale-factor error"},
    {"filter_bias_min_span_fraction", design::filter_bias_min_span_fraction, "-",
     "the shortest span, in reference_window_s, over which the filter-bias isolation's fault-model check "
     "fits the episode"},
    {"filter_bias_late_span_fraction", design::filter_bias_late_span_fraction, "-",
     "the shortest latest half-span, in reference_window_s, in which that fault must persist"},
    {"reference_max_wander_ratio", design::reference_max_wander_ratio, "-",
     "a common drift needing a wander beyond this ratio of the model's is the reference's, not the gyros'"},
    {"reference_long_windows", design::reference_long_windows, "windows",
     "the reference bias match's long window, in reference_bias_window_s"},
    {"reference_max_noise_ratio", design::reference_max_noise_ratio, "-",
     "the largest white rate noise the filter takes on, times the model's N"},
    // --- the calibration's motion fit
    {"motion_fit_block_s", design::motion_fit_block_s, "s",
     "one block of the motion fit: a slew or two, a mismatch named within ten minutes of motion"},
    {"motion_fit_blocks_in_a_row", design::motion_fit_blocks_in_a_row, "blocks",
     "blocks in a row whose fits make the case before a calibration mismatch is named"},
    {"motion_fit_min_epochs", design::motion_fit_min_epochs, "epochs",
     "a block with fewer epochs is not judged"},
};
}  // namespace key_table

const std::vector<ConfigKey>& config_keys() {
  static const std::vector<ConfigKey> keys(std::begin(key_table::kKeys), std::end(key_table::kKeys));
  return keys;
}

const std::vector<DesignConstant>& design_constants() {
  static const std::vector<DesignConstant> constants(std::begin(key_table::kConstants),
                                                     std::end(key_table::kConstants));
  return constants;
}

std::string range_text(const ConfigKey& key) {
  using namespace key_table;
  if (std::holds_alternative<bool C::*>(key.field)) return "true or false";
  if (std::holds_alternative<Quaternion C::*>(key.field)) return "unit norm";
  const ConfigLimit& lo = key.min;
  const ConfigLimit& hi = key.max;
  if (lo.edge == Edge::kNone && hi.edge == Edge::kNone) return "any";
  if (hi.edge == Edge::kNone) return (lo.edge == Edge::kOpen ? "> " : ">= ") + number_text(lo.value);
  if (lo.edge == Edge::kNone) return (hi.edge == Edge::kOpen ? "< " : "<= ") + number_text(hi.value);
  return std::string("in ") + (lo.edge == Edge::kOpen ? "(" : "[") + number_text(lo.value) + ", " +
         number_text(hi.value) + (hi.edge == Edge::kOpen ? ")" : "]");
}

bool within_range(const ConfigKey& key, double v) {
  using namespace key_table;
  if (!std::isfinite(v)) return false;
  const ConfigLimit& lo = key.min;
  const ConfigLimit& hi = key.max;
  if (lo.edge == Edge::kOpen && !(v > lo.value)) return false;
  if (lo.edge == Edge::kClosed && !(v >= lo.value)) return false;
  if (hi.edge == Edge::kOpen && !(v < hi.value)) return false;
  if (hi.edge == Edge::kClosed && !(v <= hi.value)) return false;
  return true;
}

std::string value_text(const PipelineConfig& c, const ConfigKey& key) {
  using namespace key_table;
  std::string out;
  if (const auto* d = std::get_if<double C::*>(&key.field)) {
    append_double(out, c.*(*d));
  } else if (const auto* b = std::get_if<bool C::*>(&key.field)) {
    out = (c.*(*b)) ? "true" : "false";
  } else if (const auto* o = std::get_if<std::optional<double> C::*>(&key.field)) {
    if (!(c.*(*o))) return "none";
    append_double(out, *(c.*(*o)));
  } else {
    const auto q = to_wxyz(c.*std::get<Quaternion C::*>(key.field));
    out = "[";
    for (std::size_t k = 0; k < 4; ++k) {
      if (k) out += ", ";
      append_double(out, q[k]);
    }
    out += ']';
  }
  return out;
}

}  // namespace tetra::fdi
