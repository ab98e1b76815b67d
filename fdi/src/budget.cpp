#include "tetra/fdi/budget.hpp"

#include "calibration_fit.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace tetra::fdi {

namespace {

constexpr double kNotAProbability = std::numeric_limits<double>::quiet_NaN();

//! Two-sided tail of a standard normal beyond `sigmas`.
double normal_tail(double sigmas) {
  return std::erfc(sigmas / std::sqrt(2.0));
}

}  // namespace

const Allocation kAllocations[kBudgetTestCount] = {
    {BudgetTest::kChi2, "chi2", 1.0, "per epoch: a large fault seen at once"},
    {BudgetTest::kCusum, "cusum", 10.0,
     "per epoch (1/ARL0): most of the budget's false alarms, spent on the delay of the smallest fault "
     "(h grows as ln ARL0)"},
    {BudgetTest::kJump, "jump", 1.0, "per epoch; confirmed over onset_confirm_epochs before it names a step"},
    {BudgetTest::kParityBlockMatch, "parity_block_match", kLargestShare,
     "per epoch, by Wald's bound on the block match's mean run length: a match opens the gyros' bias models "
     "(sigma carries what the blocks show), it decides nothing"},
    {BudgetTest::kGlt, "glt", 1.0, "per form and epoch: two forms, the larger decides"},
    {BudgetTest::kReferenceCheck, "reference_test", 1.0, "per sample and test of a good reference"},
    {BudgetTest::kReferenceNoiseMatch, "reference_noise_match", 1.0, "per sample, three gyros only"},
    {BudgetTest::kReferenceGate, "reference_gate", kLargestShare,
     "per sample: a good sample left out costs one sample, not a decision (rejection takes "
     "reference_gate_reset_count in a row)"},
    {BudgetTest::kReferenceBiasMatch, "reference_bias_match", kLargestShare,
     "per sample of a good reference, its mean innovation over reference_bias_window_s: a match opens the "
     "gyros' bias model and says so (noise_model), it decides nothing"},
    {BudgetTest::kMotionFit, "motion_fit", kLargestShare,
     "per block of the motion fit and hypothesis: a mismatch needs two blocks in a row, and it excludes "
     "nothing (it withholds exclusions the calibration's error could explain)"},
    {BudgetTest::kParitySpread, "parity_spread", kLargestShare,
     "per look at the sums of the parity's differences: a verdict takes the white noise the data show into "
     "every test and sigma (noise_model), it excludes nothing"},
};

double allocated_probability(const PipelineConfig& config, BudgetTest test) {
  return config.false_alarm_probability * kAllocations[static_cast<int>(test)].share;
}

double cusum_arl0_epochs(const PipelineConfig& config) {
  return 1.0 / allocated_probability(config, BudgetTest::kCusum);
}

Budget error_budget(const PipelineConfig& c, int gyros, double sample_period_s) {
  Budget b;
  b.gyros = gyros;
  b.sample_period_s = sample_period_s;
  const double epochs_per_hour = 3600.0 / sample_period_s;
  const double window_epochs = design::isolation_window_s / sample_period_s;
  const bool parity = gyros >= 4;
  using K = BudgetKind;
  if (parity) {
    b.rows.push_back({"chi2", K::kFalseAlarm, "false_alarm_probability",
                      allocated_probability(c, BudgetTest::kChi2), epochs_per_hour, "one epoch's parity"});
    b.rows.push_back({"cusum", K::kFalseAlarm, "false_alarm_probability",
                      allocated_probability(c, BudgetTest::kCusum), epochs_per_hour,
                      "mean run length between false alarms, the wander and quantization in h"});
    // The onset test names gyro i when every subset without it shows impossible motion: the true
    // hypothesis's subset beyond its margin, at most the one-axis tail, per evaluation (from
    // onset_min_post_epochs after the onset to onset_post_max_epochs).
    b.rows.push_back(
        {"onset", K::kWrongExclusion, "onset_sigma", normal_tail(c.onset_sigma),
         std::max(1.0, static_cast<double>(design::onset_post_max_epochs - design::onset_min_post_epochs)),
         "true hypothesis beyond the motion bound's margin"});
  }
  if (gyros >= 5) {
    b.rows.push_back({"glt", K::kWrongExclusion, "false_alarm_probability",
                      2.0 * allocated_probability(c, BudgetTest::kGlt), window_epochs,
                      "true hypothesis rejected by either form, per epoch of isolation_window_s"});
  }
  if (gyros == 4) {
    b.rows.push_back({"reference_window", K::kWrongExclusion, "reference_threshold_sigma",
                      std::pow(normal_tail(c.reference_threshold_sigma), design::reference_confirm_count),
                      window_epochs,
                      "a healthy gyro's window beyond the threshold, reference_confirm_count times"});
  }
  b.rows.push_back({"reference_test", K::kReference, "false_alarm_probability",
                    allocated_probability(c, BudgetTest::kReferenceCheck), 1.0,
                    "per reference sample and test"});
  b.rows.push_back({"reference_test", K::kReference, "false_alarm_probability",
                    allocated_probability(c, BudgetTest::kReferenceGate), 1.0,
                    "one sample left out (the gate), rejection after reference_gate_reset_count"});
  if (parity) {
    b.rows.push_back({"motion_fit", K::kMismatch, "false_alarm_probability",
                      allocated_probability(c, BudgetTest::kMotionFit), 3600.0 / design::motion_fit_block_s,
                      "one block's H0 rejected (a mismatch needs two in a row and every Hi rejected too)"});
  }
  if (parity) {
    // Wald's bound: each gyro's block CUSUM runs at least 1/(p·n·|S|) blocks of n epochs between false
    // matches, the first of the |S| at least 1/(p·n·|S|²): at most p·|S|² per epoch (the gyros' CUSUMs share
    // the parity, so the bound is loose by up to |S|).
    b.rows.push_back({"parity_block_match", K::kNoiseModel, "false_alarm_probability",
                      allocated_probability(c, BudgetTest::kParityBlockMatch) * gyros * gyros,
                      epochs_per_hour,
                      "a bias model opened by the parity's block means of the filter's innovations"});
    b.rows.push_back(
        {"parity_spread", K::kNoiseModel, "false_alarm_probability",
         allocated_probability(c, BudgetTest::kParitySpread), epochs_per_hour,
         "the stated white noise rejected by the parity's differences (the model then widened)"});
  }
  for (const char* signature : {"repeated", "zero", "variance", "noise_level", "recurring_spikes"}) {
    b.rows.push_back({signature, K::kWrongExclusion, "", kNotAProbability, 1.0,
                      "the gyro's own samples against a count or ratio: not a probability"});
  }
  for (const BudgetRow& row : b.rows) {
    if (!std::isfinite(row.per_evaluation)) continue;
    if (row.kind == K::kFalseAlarm) b.false_alarms_per_hour += row.total();
    if (row.kind == K::kWrongExclusion) b.wrong_exclusion_per_episode += row.total();
  }
  return b;
}

std::string to_text(const Budget& b) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "error budget: %d gyros, sample period %g s\n", b.gyros,
                b.sample_period_s);
  out += line;
  for (const BudgetRow& r : b.rows) {
    const char* kind = r.kind == BudgetKind::kFalseAlarm       ? "false alarm"
                       : r.kind == BudgetKind::kWrongExclusion ? "wrong exclusion"
                       : r.kind == BudgetKind::kMismatch       ? "calibration mismatch"
                       : r.kind == BudgetKind::kNoiseModel     ? "noise model widened"
                                                               : "reference rejected";
    if (std::isfinite(r.per_evaluation)) {
      const char* per = r.kind == BudgetKind::kFalseAlarm || r.kind == BudgetKind::kMismatch ||
                                r.kind == BudgetKind::kNoiseModel
                            ? "/h"
                        : r.kind == BudgetKind::kWrongExclusion ? "/episode"
                                                                : "/sample";
      std::snprintf(line, sizeof line, "  %-18s %-18s %-40s %9.3g x %-9.4g = %9.3g %s  (%s)\n", r.source,
                    kind, r.key, r.per_evaluation, r.evaluations, r.total(), per, r.note);
    } else {
      std::snprintf(line, sizeof line, "  %-18s %-18s %-40s %s\n", r.source, kind, "-", r.note);
    }
    out += line;
  }
  std::snprintf(line, sizeof line,
                "  total: %.3g false alarms per 1,000 h; wrong exclusion at most %.3g per fault episode (the "
                "sources with a probability)\n",
                b.false_alarms_per_hour * 1000.0, b.wrong_exclusion_per_episode);
  out += line;
  return out;
}

}  // namespace tetra::fdi
