#pragma once
// The perturbation families' campaign (docs/fdi_validation.md, "Perturbation families"): one generated run
// (sim/perturbation_families.hpp) through the pipeline, judged against the promises — no exclusion of a gyro
// without a fault begun, no exclusion in a fault-free run, never LOST from one fault, sigma honest per run —
// and the figures of a family over many runs.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "campaign.hpp"
#include "tetra/sim/perturbation_families.hpp"
#include "tetra/sim/random.hpp"  // splitmix64

namespace tetra::test {

//! Sigma's honesty is judged from here on [s]: the first reference sample (t = 0) or the initial attitude
//! then holds, and a run's first seconds are the same in every family.
inline constexpr double kHonestyFrom_s = 20.0;
//! A run is honest when at least this share of its axis-epochs is within 3σ (a consistent Gaussian error
//! gives 99.73 %; one run's epochs are correlated over tens of seconds, so its share scatters below that).
inline constexpr double kMinWithin3Sigma = 0.97;
//! ...and its per-axis NEES (mean e²/σ², 1 expected) is at most this.
inline constexpr double kMaxNeesPerAxis = 2.0;

struct FamilyVerdict {
  bool wrong_exclusion = false;     //!< a gyro excluded before any fault of its own began
  bool exclusion_no_fault = false;  //!< an exclusion in a run without any gyro fault
  bool lost =
      false;  //!< a `lost` event (exclusions left the rate unobservable; one epoch short of samples is not)
  bool healthy_reference_rejected = false;  //!< `reference_rejected` of a reference without a failure
  bool calibration_mismatch = false;        //!< a `calibration_mismatch` named
  //! Decisions whose own rows the arbiter's rule does not rebuild (isolated: its gyro; reference_rejected:
  //! kReject; noise_model: kMatchDrift)
  int unexplained = 0;
  double within = 1.0;  //!< share of axis-epochs with |e| ≤ 3σ from kHonestyFrom_s
  Eigen::Vector3d nees = Eigen::Vector3d::Zero();  //!< per-axis mean e²/σ² over the same epochs
  double worst_sigmas = 0.0;                       //!< largest |e|/σ of an axis
  int beyond_protection = 0;            //!< axis-epochs with |e| above the (finite) protection level
  double worst_protection_ratio = 0.0;  //!< largest |e|/PL of an axis (0 where PL is +∞)
  double beyond_from_s = -1.0;          //!< [s] the first and last epoch above it (−1: none)
  double beyond_until_s = -1.0;
  std::optional<double> flagged_after_s;  //!< [s] first detection, reference rejection or noise_model after
                                          //!< the perturbation began
  //! Sigma meets the per-run criterion over the epochs from the first flag on: what the perturbation did
  //! before anything could see it is the protection level's to bound, not sigma's (docs/fdi.md).
  bool honest_after_flag = false;
  std::string events;  //!< the run's events, for a failure report
};

inline double perturbation_start_s(const sim::PerturbedRun& r) {
  double t = r.reference_fault_at_s >= 0.0 ? r.reference_fault_at_s : 1e300;
  for (const auto& f : r.options.faults) t = std::min(t, f.at_s);
  return t < 1e300 ? t : 0.0;
}

//! Sigma's honesty over a run's epochs from `from_s` on.
struct Honesty {
  double within = 1.0;                             //!< share of axis-epochs with |e| ≤ 3σ
  Eigen::Vector3d nees = Eigen::Vector3d::Zero();  //!< per-axis mean e²/σ²
  double worst_sigmas = 0.0;                       //!< largest |e|/σ of an axis
  double worst_error_deg = 0.0;                    //!< [deg] largest |e| of an axis
  int beyond_protection = 0;                       //!< axis-epochs with |e| above the protection level
  double worst_protection_ratio = 0.0;             //!< largest |e|/PL of an axis
  double beyond_from_s = -1.0;                     //!< [s] the first and last epoch above it (−1: none)
  double beyond_until_s = -1.0;
};

inline Honesty honesty(const CampaignRun& run, double from_s) {
  Honesty h;
  int epochs = 0;
  int inside = 0;
  for (std::size_t k = 0; k < run.time_s.size(); ++k) {
    if (run.time_s[k] < from_s) continue;
    ++epochs;
    for (int a = 0; a < 3; ++a) {
      const double z = std::abs(run.error_rad[k][a]) / run.sigma_rad[k][a];
      inside += z <= 3.0 ? 1 : 0;
      h.nees[a] += z * z;
      h.worst_sigmas = std::max(h.worst_sigmas, z);
      h.worst_error_deg = std::max(h.worst_error_deg, std::abs(run.error_rad[k][a]) * kRadToDeg);
      // An alarm standing (SUSPECT: a fault detected, not yet isolated; LOST) is what the protection level
      // is not for: it bounds the error without an alarm.
      const bool alarm = run.mode[k] == fdi::Mode::kSuspect || run.mode[k] == fdi::Mode::kLost;
      const double pl = alarm ? 0.0 : std::abs(run.error_rad[k][a]) / run.protection_level_rad[k][a];
      h.beyond_protection += pl > 1.0 ? 1 : 0;
      if (pl > 1.0) {
        if (h.beyond_from_s < 0.0) h.beyond_from_s = run.time_s[k];
        h.beyond_until_s = run.time_s[k];
      }
      h.worst_protection_ratio = std::max(h.worst_protection_ratio, pl);
    }
  }
  if (epochs > 0) {
    h.within = inside / (3.0 * epochs);
    h.nees /= epochs;
  }
  return h;
}

//! A decision event's rows rebuild it under the arbiter's rule (other events: nothing to rebuild).
inline bool explained(const fdi::FdiEvent& e) {
  switch (e.type) {
    case fdi::EventType::kIsolated:
      return fdi::ruling_of(e) == e.gyro.value_or(0);
    case fdi::EventType::kReferenceRejected:
      return fdi::reference_ruling_of(e) == fdi::ReferenceDecision::kReject;
    case fdi::EventType::kNoiseModel:
      return fdi::noise_ruling_of(e);
    case fdi::EventType::kCalibrationMismatch:
      return fdi::calibration_ruling_of(e);
    default:
      return true;
  }
}

//! One perturbed run through the pipeline, every accepted epoch's error, sigma and protection level kept.
inline CampaignRun run_family_member(const sim::PerturbedRun& r) {
  fdi::PipelineConfig config;
  if (r.sample_period_s > 0.0) config.sample_period_s = r.sample_period_s;
  if (r.max_angular_acceleration_dps2 > 0.0)
    config.max_angular_acceleration_dps2 = r.max_angular_acceleration_dps2;
  CampaignOptions options;
  options.keep_errors = true;
  options.gap_from_s = r.gap_from_s;
  options.gap_until_s = r.gap_until_s;
  return run_campaign(r.scenario, r.options, r.calibration, config, options);
}

inline FamilyVerdict judge_run(const sim::PerturbedRun& r) {
  const CampaignRun run = run_family_member(r);
  FamilyVerdict v;
  const int n = r.scenario.unit.gyro_count();
  const double start = perturbation_start_s(r);
  for (const auto& e : run.events) {
    const double t = ns_to_seconds(e.stamp_ns);
    if (e.type == fdi::EventType::kLost) v.lost = true;
    if (e.type == fdi::EventType::kReferenceRejected && r.reference_failure == sim::ReferenceFailure::kNone)
      v.healthy_reference_rejected = true;
    v.unexplained += explained(e) ? 0 : 1;
    v.calibration_mismatch |= e.type == fdi::EventType::kCalibrationMismatch;
    if ((e.type == fdi::EventType::kDetected || e.type == fdi::EventType::kReferenceRejected ||
         e.type == fdi::EventType::kNoiseModel || e.type == fdi::EventType::kCalibrationMismatch) &&
        t >= start && !v.flagged_after_s)
      v.flagged_after_s = t - start;
    if (e.type != fdi::EventType::kIsolated) continue;
    if (r.options.faults.empty()) v.exclusion_no_fault = true;
    const bool faulty = std::any_of(r.options.faults.begin(), r.options.faults.end(),
                                    [&](const sim::FaultSpec& f) { return f.gyro == e.gyro && f.at_s <= t; });
    if (!faulty) v.wrong_exclusion = true;
  }
  const Honesty whole = honesty(run, kHonestyFrom_s);
  v.within = whole.within;
  v.nees = whole.nees;
  v.worst_sigmas = whole.worst_sigmas;
  v.beyond_protection = whole.beyond_protection;
  v.worst_protection_ratio = whole.worst_protection_ratio;
  v.beyond_from_s = whole.beyond_from_s;
  v.beyond_until_s = whole.beyond_until_s;
  if (v.flagged_after_s) {
    const Honesty after = honesty(run, std::max(kHonestyFrom_s, start + *v.flagged_after_s));
    v.honest_after_flag = after.within >= kMinWithin3Sigma && after.nees.maxCoeff() <= kMaxNeesPerAxis;
  }
  v.events = describe(run, n);
  return v;
}

//! A family's figures over its runs.
struct FamilyFigures {
  int runs = 0;
  int wrong_exclusions = 0;
  int exclusions_without_fault = 0;
  int lost = 0;
  int healthy_reference_rejected = 0;  //!< runs whose healthy reference was rejected
  int unexplained = 0;                 //!< decision events their own rows do not rebuild
  int lost_from_one_fault = 0;         //!< LOST where one fault left three gyros or more
  int dishonest = 0;                   //!< runs failing the per-run criterion whose twin meets it
  int twin_dishonest = 0;              //!< twins failing it (the fault-free character)
  int honest_from_flag = 0;  //!< runs honest only from their first flag on (the perturbation unseen before)
  int below_within = 0;      //!< runs below kMinWithin3Sigma
  int above_nees = 0;        //!< runs above kMaxNeesPerAxis on an axis
  Eigen::Vector3d nees_sum = Eigen::Vector3d::Zero();  //!< Σ over the runs of each axis's NEES
  double worst_within = 1.0;
  double worst_nees = 0.0;
  int flagged = 0;
  double max_flag_delay_s = 0.0;
  std::vector<double> flag_delays_s;
  int beyond_protection = 0;            //!< runs with an axis-epoch above the protection level
  double worst_protection_ratio = 0.0;  //!< largest |e|/PL over the runs
  std::string failures;                 //!< label, figures and events of every run that broke a promise
};

//! A run's sigma meets the per-run criterion over the whole run, or from an honest flag on.
inline bool honest(const FamilyVerdict& v) {
  return (v.within >= kMinWithin3Sigma && v.nees.maxCoeff() <= kMaxNeesPerAxis) || v.honest_after_flag;
}

//! The run's sigma is materially worse than its twin's: a per-axis NEES above kTwinNeesRatio times the twin's
//! largest, or a within-3σ share more than kTwinWithinMargin below the twin's. The twin shares the noise
//! samples but not the filter's path after the perturbation, so a run near the criterion whose twin is just
//! inside it (NEES 2.02 against 1.99 across a gap) is the same fault-free character, not the perturbation's.
inline constexpr double kTwinNeesRatio = 1.25;
inline constexpr double kTwinWithinMargin = 0.01;
inline bool worse_than_twin(const FamilyVerdict& v, const FamilyVerdict& twin) {
  return v.nees.maxCoeff() > kTwinNeesRatio * twin.nees.maxCoeff() ||
         v.within < twin.within - kTwinWithinMargin;
}

//! The same run over other draws of the simulator's noise, each against its own twin: the paired difference
//! of the largest per-axis NEES (run − twin) averaged over the draws, and its standard error.
struct DrawComparison {
  int draws = 0;
  double mean_difference = 0.0;  //!< [-] mean over the draws of max NEES(run) − max NEES(twin)
  double standard_error = 0.0;   //!< [-] its standard error (sample σ/√draws)
  int runs_failing = 0;          //!< draws whose run fails the per-run criterion
  int twins_failing = 0;         //!< draws whose twin fails it
  int only_run_fails = 0;        //!< draws whose run fails the criterion and whose twin meets it
  int only_twin_fails = 0;       //!< draws whose twin fails it and whose run meets it
  //! One-sided exact p-value of McNemar's test that the run fails the criterion no more often than its twin:
  //! P(X ≥ only_run_fails), X ~ Binomial(only_run_fails + only_twin_fails, ½).
  double failure_p = 1.0;
  Eigen::Vector3d mean_run_nees = Eigen::Vector3d::Zero();   //!< per-axis NEES averaged over the draws' runs
  Eigen::Vector3d mean_twin_nees = Eigen::Vector3d::Zero();  //!< ...and over their twins
};

//! Draws of the noise a run charged against its one twin is judged over (the perturbation, motion, unit and
//! fusion as they are; the simulator's seed replaced by splitmix64(seed + k)).
inline constexpr int kChargeDraws = 20;
//! The perturbation is charged when it makes the largest per-axis NEES worse on average over the draws by
//! more than this many standard errors of the mean paired difference (one-sided: a perturbation that changes
//! nothing is charged with probability ≈ 2.3 %; the undetected scale change that motivated the check,
//! fault-in-slew #124 seed 1 before the parity's block match, stood at +0.71 ± 0.20, 3.6 standard errors)...
inline constexpr double kChargeStandardErrors = 2.0;
//! ...or when it makes the run fail the per-run criterion more often than its twin at this one-sided level of
//! McNemar's exact test (a NEES whose spread hides a shift of its mean: a reference bias ramp of 20″, 8 of 20
//! draws failing against 1 twin). Both together charge a perturbation that changes nothing with probability
//! ≤ 5 %.
inline constexpr double kChargeFailureP = 0.025;

//! P(X ≥ k), X ~ Binomial(n, ½).
inline double binomial_half_tail(int k, int n) {
  double term = std::pow(0.5, n);  // C(n, 0)/2ⁿ
  double tail = 0.0;
  for (int j = 0; j <= n; ++j) {
    if (j >= k) tail += term;
    term *= static_cast<double>(n - j) / (j + 1.0);
  }
  return tail;
}

inline DrawComparison compare_over_draws(const sim::PerturbedRun& r) {
  DrawComparison c;
  double sum = 0.0;
  double sum2 = 0.0;
  for (int k = 0; k < kChargeDraws; ++k) {
    sim::PerturbedRun drawn = r;
    drawn.options.seed = sim::splitmix64(r.options.seed + static_cast<std::uint64_t>(k) + 1);
    const FamilyVerdict v = judge_run(drawn);
    const FamilyVerdict t = judge_run(sim::unperturbed_twin(drawn));
    const double d = v.nees.maxCoeff() - t.nees.maxCoeff();
    c.mean_run_nees += v.nees / kChargeDraws;
    c.mean_twin_nees += t.nees / kChargeDraws;
    sum += d;
    sum2 += d * d;
    const bool run_fails = v.within < kMinWithin3Sigma || v.nees.maxCoeff() > kMaxNeesPerAxis;
    const bool twin_fails = t.within < kMinWithin3Sigma || t.nees.maxCoeff() > kMaxNeesPerAxis;
    c.runs_failing += run_fails ? 1 : 0;
    c.twins_failing += twin_fails ? 1 : 0;
    c.only_run_fails += run_fails && !twin_fails ? 1 : 0;
    c.only_twin_fails += twin_fails && !run_fails ? 1 : 0;
  }
  c.failure_p = binomial_half_tail(c.only_run_fails, c.only_run_fails + c.only_twin_fails);
  c.draws = kChargeDraws;
  c.mean_difference = sum / c.draws;
  const double var =
      std::max(sum2 / c.draws - c.mean_difference * c.mean_difference, 0.0) * c.draws / (c.draws - 1.0);
  c.standard_error = std::sqrt(var / c.draws);
  return c;
}

//! Whether a run's sigma is charged to its perturbation: it fails the per-run criterion, its twin meets it
//! and the run is materially worse (worse_than_twin) — and, since one twin is a single paired draw of a NEES
//! whose few degrees of freedom scatter it widely, the same run over kChargeDraws other draws of the noise
//! confirms it (compare_over_draws, kChargeStandardErrors, kChargeFailureP): a run that is only a statistical
//! borderline is not charged; its draws are written to `note` (the sweep prints them).
inline bool charged(const sim::PerturbedRun& r, const FamilyVerdict& v, const FamilyVerdict& twin,
                    std::string& note) {
  if (honest(v) || !honest(twin) || !worse_than_twin(v, twin)) return false;
  const DrawComparison c = compare_over_draws(r);
  const bool confirmed =
      c.mean_difference > kChargeStandardErrors * c.standard_error || c.failure_p < kChargeFailureP;
  char line[400];
  std::snprintf(line, sizeof line,
                "%s\n  over %d other draws of the noise: largest per-axis NEES run - twin %+.3f +- %.3f "
                "(standard error), runs failing %d, twins failing %d (McNemar p %.3f): %s\n",
                r.label.c_str(), c.draws, c.mean_difference, c.standard_error, c.runs_failing,
                c.twins_failing, c.failure_p,
                confirmed ? "charged" : "a statistical borderline, not charged");
  note = line;
  return confirmed;
}

//! One run and its unperturbed twin (sim::unperturbed_twin) into a family's figures. Sigma is charged to the
//! perturbation when `dishonest` (charged()); a twin that fails the criterion is the fusion's fault-free
//! character over that motion and noise (counted apart, `twin`).
inline void add_run(FamilyFigures& f, const sim::PerturbedRun& r, const FamilyVerdict& v,
                    const FamilyVerdict& twin, bool lost_allowed, bool dishonest) {
  ++f.runs;
  f.wrong_exclusions += v.wrong_exclusion ? 1 : 0;
  f.exclusions_without_fault += v.exclusion_no_fault ? 1 : 0;
  f.lost += v.lost ? 1 : 0;
  f.lost_from_one_fault += v.lost && !lost_allowed ? 1 : 0;
  f.healthy_reference_rejected += v.healthy_reference_rejected ? 1 : 0;
  f.unexplained += v.unexplained;
  f.dishonest += dishonest ? 1 : 0;
  f.twin_dishonest += honest(twin) ? 0 : 1;
  f.honest_from_flag +=
      (v.within < kMinWithin3Sigma || v.nees.maxCoeff() > kMaxNeesPerAxis) && v.honest_after_flag ? 1 : 0;
  f.below_within += v.within < kMinWithin3Sigma ? 1 : 0;
  f.above_nees += v.nees.maxCoeff() > kMaxNeesPerAxis ? 1 : 0;
  f.nees_sum += v.nees;
  f.worst_within = std::min(f.worst_within, v.within);
  f.worst_nees = std::max(f.worst_nees, v.nees.maxCoeff());
  f.beyond_protection += v.beyond_protection > 0 ? 1 : 0;
  f.worst_protection_ratio = std::max(f.worst_protection_ratio, v.worst_protection_ratio);
  if (v.flagged_after_s) {
    ++f.flagged;
    f.flag_delays_s.push_back(*v.flagged_after_s);
    f.max_flag_delay_s = std::max(f.max_flag_delay_s, *v.flagged_after_s);
  }
  if (v.wrong_exclusion || v.exclusion_no_fault || (v.lost && !lost_allowed) || dishonest ||
      v.beyond_protection > 0) {
    char line[320];
    std::snprintf(
        line, sizeof line,
        "  %.2f %% within 3 sigma, NEES %.2f %.2f %.2f, worst %.1f sigma, |e|/PL %.2f%s%s%s (twin: %.2f %%, "
        "NEES %.2f %.2f %.2f)\n",
        100.0 * v.within, v.nees[0], v.nees[1], v.nees[2], v.worst_sigmas, v.worst_protection_ratio,
        v.wrong_exclusion ? ", wrong exclusion" : "", v.exclusion_no_fault ? ", exclusion without fault" : "",
        v.lost ? ", LOST" : "", 100.0 * twin.within, twin.nees[0], twin.nees[1], twin.nees[2]);
    f.failures += r.label + "\n" + line + v.events;
  }
}

inline void print_figures_header() {
  std::printf("%-36s %5s %5s %8s %4s %7s %9s %4s %9s %6s %6s %8s %7s %16s %7s %11s %9s %8s %7s\n", "family",
              "runs", "wrong", "no-fault", "LOST", "ref-rej", "dishonest", "twin", "from flag", "<97%",
              "NEES>2", "worst<3s", "worstNEES", "mean NEES x y z", "flagged", "median flag", "max flag",
              ">PL", "e/PL");
}

inline void print_figures(const std::string& name, FamilyFigures f) {
  std::sort(f.flag_delays_s.begin(), f.flag_delays_s.end());
  const double median = f.flag_delays_s.empty() ? 0.0 : f.flag_delays_s[f.flag_delays_s.size() / 2];
  const Eigen::Vector3d mean = f.nees_sum / std::max(f.runs, 1);
  std::printf(
      "%-36s %5d %5d %8d %4d %7d %9d %4d %9d %6d %6d %7.2f%% %9.2f %5.2f %4.2f %4.2f %7d %9.1f s %7.1f s %8d "
      "%7.2f\n",
      name.c_str(), f.runs, f.wrong_exclusions, f.exclusions_without_fault, f.lost,
      f.healthy_reference_rejected, f.dishonest, f.twin_dishonest, f.honest_from_flag, f.below_within,
      f.above_nees, 100.0 * f.worst_within, f.worst_nees, mean[0], mean[1], mean[2], f.flagged, median,
      f.max_flag_delay_s, f.beyond_protection, f.worst_protection_ratio);
}

}  // namespace tetra::test
