// The perturbation families' campaign (docs/fdi_validation.md, "Perturbation families"): every family of
// sim/perturbation_families.hpp as its own seeded generator, a cheap subset in ctest (TETRA_FAMILY_RUNS runs
// per family, default below; TETRA_FAMILY_SEED the seed, default 1), the long sweep in
// bench/perturbation_sweep.sh. Asserted per family: no exclusion of a gyro without a fault begun, no
// exclusion in a fault-free run, never LOST from one fault, and every run's sigma honest (≥ 97 % of
// axis-epochs within 3σ, per-axis NEES ≤ 2). The figures are printed per family.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "family_campaign.hpp"

namespace tetra {
namespace {

std::uint64_t env_count(const char* name, std::uint64_t fallback) {
  const char* v = std::getenv(name);
  const long n = v != nullptr ? std::strtol(v, nullptr, 10) : 0;
  return n > 0 ? static_cast<std::uint64_t>(n) : fallback;
}

//! Runs `fallback` (or TETRA_FAMILY_RUNS) indices of `family`, prints its figures and each case's, and
//! checks the promises: no exclusion of a gyro without a fault begun, none in a fault-free run, never LOST
//! from one fault, in every case; sigma honest per run (sim::unperturbed_twin, family_campaign.hpp) in every
//! case but the `limits` — the cases docs/fdi.md states the data cannot (yet) cover, whose figures are
//! printed; and the error within the protection level wherever no alarm stands (SUSPECT, LOST) in every case
//! but the `pl_limits` — a fault of the reference, which the level does not bound, or two faults.
void check_family(sim::Family family, std::uint64_t fallback, const std::set<std::string>& limits = {},
                  const std::set<std::string>& pl_limits = {}) {
  const std::uint64_t runs = env_count("TETRA_FAMILY_RUNS", fallback);
  const std::uint64_t seed = env_count("TETRA_FAMILY_SEED", 1);
  test::FamilyFigures f;
  std::map<std::string, test::FamilyFigures> cases;
  std::string borderline;  //!< runs worse than their one twin, judged over other draws of the noise
  for (std::uint64_t i = 0; i < runs; ++i) {
    const sim::PerturbedRun r = sim::perturbed_run(family, seed, i);
    // With three gyros (redundancy exhausted) or two faults, an exclusion leaves the rate unobservable.
    const bool lost_allowed = r.scenario.unit.gyro_count() - 1 < 3 || r.options.faults.size() > 1;
    const test::FamilyVerdict v = test::judge_run(r);
    const test::FamilyVerdict twin = test::judge_run(sim::unperturbed_twin(r));
    std::string note;
    const bool dishonest = test::charged(r, v, twin, note);
    borderline += note;
    test::add_run(f, r, v, twin, lost_allowed, dishonest);
    test::add_run(cases[r.case_name], r, v, twin, lost_allowed, dishonest);
  }
  test::print_figures_header();
  test::print_figures(std::string(sim::family_name(family)), f);
  for (const auto& [name, c] : cases)
    test::print_figures("  " + name + (limits.count(name) ? " (limit)" : ""), c);
  if (!borderline.empty())
    std::printf("runs worse than their twin, over other draws of the noise:\n%s", borderline.c_str());
  for (const auto& [name, c] : cases) {
    EXPECT_EQ(c.wrong_exclusions, 0) << name << "\n" << c.failures;
    EXPECT_EQ(c.exclusions_without_fault, 0) << name << "\n" << c.failures;
    EXPECT_EQ(c.lost_from_one_fault, 0) << name << "\n" << c.failures;
    EXPECT_EQ(c.unexplained, 0) << name << ": decisions their rows do not rebuild";
    if (limits.count(name) == 0) {
      EXPECT_EQ(c.dishonest, 0) << name << "\n" << c.failures;
    }
    if (pl_limits.count(name) == 0) {
      EXPECT_EQ(c.beyond_protection, 0) << name << "\n" << c.failures;
    }
  }
}

TEST(PerturbationFamilies, GeneratorsArePureFunctionsOfSeedAndIndex) {
  for (const auto family : sim::all_families()) {
    const auto a = sim::perturbed_run(family, 3, 17);
    (void)sim::perturbed_run(family, 4, 2);  // a draw in between changes nothing
    const auto b = sim::perturbed_run(family, 3, 17);
    EXPECT_EQ(a.label, b.label);
    EXPECT_EQ(a.options.seed, b.options.seed);
    EXPECT_NE(a.label, sim::perturbed_run(family, 3, 18).label);
    EXPECT_EQ(sim::family_from_name(sim::family_name(family)), family);
    EXPECT_TRUE(sim::validate_scenario(a.scenario).ok()) << a.label;
  }
}

// A scale change too small for the detectors: +2.8 % on the gyro along X in the middle of a slew about −Y,
// N = 6 with the reference (fault-in-slew #124). The slew never shows it; afterwards it is a rate error of
// the attitude control's wobble times 2.8 % (≈ 4.5e-5 deg/s, a quarter of the CUSUM's 2e-4), which the bias
// model did not allow and the parity's block means show (docs/fdi.md, "A slow error below the detectors").
// Over the 20 draws of the noise the sweep judges such a run by (compare_over_draws): before the block match
// 15 runs failed the per-run criterion against 3 twins (12 where the twin met it, none the other way: McNemar
// p 2e-4) and the mean x-axis NEES (the axis of the error) was 2.32; with it 3 against 3 (2 and 2, p 0.69)
// and 1.73 (the twins' 1.04: what is left is the time before the match, docs/fdi.md); with the blocks judged
// on white innovations and the match at the largest share, 1 against 3 and 1.29. Asserted: the run fails the
// criterion no more often than its twin (p ≥ kChargeFailureP) and the mean x-axis NEES is at most 2, the
// per-run bound.
TEST(PerturbationFamilies, AScaleChangeBelowTheDetectorsLeavesSigmaHonest) {
  const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kFaultInSlew, 1, 124);
  const test::DrawComparison c = test::compare_over_draws(r);
  std::printf(
      "%s: over %d draws %+.3f +- %.3f, runs failing %d, twins failing %d, McNemar p %.3f, mean x NEES "
      "%.2f (twins %.2f)\n",
      r.label.c_str(), c.draws, c.mean_difference, c.standard_error, c.runs_failing, c.twins_failing,
      c.failure_p, c.mean_run_nees.x(), c.mean_twin_nees.x());
  EXPECT_GE(c.failure_p, test::kChargeFailureP);
  EXPECT_LE(c.mean_run_nees.x(), test::kMaxNeesPerAxis);
}

// The two runs the sweep once charged for noise ×8 at a slew's start (N = 6, fault-in-slew #117) and for
// drops and jitter (N = 5, data-path #196): over 20 other draws of the noise the perturbed run is no worse
// than its twin — largest per-axis NEES run − twin −0.025 ± 0.030 and −0.090 ± 0.037, runs failing the
// per-run criterion 1 and 2 against twins 2 and 3 — so their NEES of 2.21 and 2.43 are the spread of a χ² of
// few degrees of freedom (the twins reach 2.74 on the same runs), not their perturbation. Asserted: neither
// is charged (compare_over_draws: paired mean ≤ 2 standard errors, McNemar p ≥ 0.025).
TEST(PerturbationFamilies, TheBorderlineRunsAreTheNoiseNotTheirPerturbation) {
  for (const auto& [family, index] :
       {std::pair{sim::Family::kFaultInSlew, 117}, {sim::Family::kDataPath, 196}}) {
    const sim::PerturbedRun r = sim::perturbed_run(family, 1, static_cast<std::uint64_t>(index));
    const test::DrawComparison c = test::compare_over_draws(r);
    std::printf("%s: %+.3f +- %.3f, runs failing %d, twins failing %d, McNemar p %.3f\n", r.label.c_str(),
                c.mean_difference, c.standard_error, c.runs_failing, c.twins_failing, c.failure_p);
    EXPECT_LE(c.mean_difference, test::kChargeStandardErrors * c.standard_error) << r.label;
    EXPECT_GE(c.failure_p, test::kChargeFailureP) << r.label;
  }
}

// ctest's subset: each family's index cycle covers its cases (fault kind × timing × N, failure kind, ...)
// once or more; bench/perturbation_sweep.sh runs 300 per family.
TEST(PerturbationFamilies, FaultInSlew) {
  check_family(sim::Family::kFaultInSlew, 42);
}
TEST(PerturbationFamilies, DataPath) {
  check_family(sim::Family::kDataPath, 12);
}
TEST(PerturbationFamilies, Gap) {
  check_family(sim::Family::kGap, 18);
}
// A reference bias of 10–40″: a step is caught by the step test from about 10″ (6 of 8 at 10″, all from 12″;
// the rest the filter follows within its noise), a ramp over 20–60 s is a common drift to the data (matched,
// the reference kept: sigma the drift's, the protection level the reference's from the match on); a late
// reference at a steady rate is an offset: docs/fdi.md, "Reference consistency", Limits. Before a flag the
// protection level takes the reference samples it anchors on as true.
TEST(PerturbationFamilies, Reference) {
  check_family(sim::Family::kReference, 15, {"bias-step", "bias-ramp"}, {"bias-step", "bias-ramp", "late"});
}
TEST(PerturbationFamilies, Calibration) {
  check_family(sim::Family::kCalibration, 27);
}
TEST(PerturbationFamilies, CalibrationWithoutNoise) {
  check_family(sim::Family::kCalibrationWithoutNoise, 18);
}
// Three gyros: a noise increase is named by the gyro's own level within seconds, a bias or a ramp by the
// reference's innovations, and each is covered from then on (docs/fdi_validation.md, "Perturbation
// families"). The protection level bounds one gyro fault: two that cancel in the parity are beyond it.
TEST(PerturbationFamilies, SecondFault) {
  check_family(sim::Family::kSecondFault, 12, {}, {"two biases cancelling in the parity"});
}
// A warm-up's common drift, which the parity cannot see, is matched from the reference's mean innovation (a
// noise_model event, the gyros' bias model opened, the reference kept) once that mean is significant; the
// protection level bounds single-gyro faults, and before the match the drift is not one (docs/fdi.md, "A
// common drift below the detectors").
TEST(PerturbationFamilies, WarmUp) {
  check_family(sim::Family::kWarmUp, 54, {},
               {"fault-free, reference", "bias, reference", "stuck, reference", "zero, reference"});
}

// A data-sheet calibration (scale factors 10–30 % off): the parity follows the motion in every block. The
// motion fit names it (calibration_mismatch) and the parity's evidence excludes nothing from then on; a
// gyro's own signal (stuck, zero) still excludes it. Sigma does not cover such a calibration: the event says
// so (docs/fdi.md, "A calibration that does not describe the unit"), so sigma and the protection level are
// this family's limits; every run that keeps a parity must name the mismatch, no run may exclude a healthy
// gyro (the parity beyond its threshold from the first epoch has no fault-free history: Hcal stands).
TEST(PerturbationFamilies, DataSheet) {
  const std::set<std::string> cases = {"fault-free", "stuck", "zero", "bias"};
  check_family(sim::Family::kDataSheet, 27, cases, cases);
  std::string unnamed;
  for (std::uint64_t i = 0; i < 27; ++i) {
    const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kDataSheet, 1, i);
    // Four gyros less a stuck or zero one (its own signal excludes it) leave no parity: nothing to fit.
    const bool own_signal_fault =
        !r.options.faults.empty() && r.options.faults[0].kind != sim::FaultKind::kBias;
    const bool parity_left = r.scenario.unit.gyro_count() > 4 || !own_signal_fault;
    if (parity_left && !test::judge_run(r).calibration_mismatch) unnamed += r.label + "\n";
    // The unit's own calibration on the same data names nothing.
    EXPECT_FALSE(test::judge_run(sim::unperturbed_twin(r)).calibration_mismatch) << r.label;
  }
  EXPECT_TRUE(unnamed.empty()) << "no calibration_mismatch:\n" << unnamed;
}

// A unit whose white noise and bias instability are 0.5–3 times what its noise: section states, flown on the
// stated figures: the parity's spread shows the white noise and every test and sigma take it (docs/fdi.md, "A
// unit noisier than its noise: section"). Every promise holds; a run whose white noise is above the stated
// names it (noise_model).
TEST(PerturbationFamilies, NoisyUnit) {
  check_family(sim::Family::kNoisyUnit, 27);
}

TEST(PerturbationFamilies, ABiasInstabilityBeyondTheStatedIsMatchedByTheParityBlocks) {
  // A unit whose bias instability is 2.8–2.9 times the stated (N = 4 and 6, a 1 Hz reference, no fault):
  // the parity's block means of the filter's innovations were judged against 1/Σ|w_i|² + v_i, as if the
  // filter's bias error stood still over a 30-s block, so a fault-free unit's u_i ran about 20 times below
  // χ²₁ and these runs' (0.5–13) never matched: sigma 0.8″ for errors of per-axis NEES 2.4–2.6 and 2.4 (runs
  // worse than their twins over 20 draws of the noise: charged). A filter whose model holds has white
  // innovations, so v_i enters the block's mean as v_i/n (docs/fdi.md, "A slow error below the detectors"):
  // matched after 180 s, a noise_model event says so (its row parity_block_match rebuilds it), sigma honest
  // over the run. Runs of the sweep (seed 3): noisy-unit #35, #263.
  for (const std::uint64_t index : {35u, 263u}) {
    const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kNoisyUnit, 3, index);
    const test::FamilyVerdict v = test::judge_run(r);
    std::printf("%s: within 3 sigma %.2f %%, NEES %.2f %.2f %.2f, flagged after %.0f s\n", r.label.c_str(),
                100.0 * v.within, v.nees.x(), v.nees.y(), v.nees.z(), v.flagged_after_s.value_or(-1.0));
    EXPECT_TRUE(test::honest(v)) << r.label << "\n" << v.events;
    EXPECT_TRUE(v.flagged_after_s.has_value()) << r.label << "\n" << v.events;
    EXPECT_EQ(v.unexplained, 0) << r.label << "\n" << v.events;
  }
}

//! One run of the sweep judged, its figures printed (the test's record of what it measured).
test::FamilyVerdict judged(const sim::PerturbedRun& r) {
  const test::FamilyVerdict v = test::judge_run(r);
  std::printf("%s: within 3 sigma %.2f %%, NEES %.2f %.2f %.2f\n", r.label.c_str(), 100.0 * v.within,
              v.nees.x(), v.nees.y(), v.nees.z());
  return v;
}

//! A noisy unit's run: honest, and the noise model's excess named (a noise_model event).
test::FamilyVerdict expect_named_and_honest(const sim::PerturbedRun& r) {
  const test::FamilyVerdict v = judged(r);
  EXPECT_TRUE(test::honest(v)) << r.label << "\n" << v.events;
  EXPECT_NE(v.events.find("noise_model"), std::string::npos) << r.label << "\n" << v.events;
  return v;
}

//! A warm-up's run with a healthy tracker: the tracker kept, every decision explained, sigma honest.
test::FamilyVerdict expect_tracker_kept_and_honest(const sim::PerturbedRun& r) {
  const test::FamilyVerdict v = judged(r);
  EXPECT_FALSE(v.healthy_reference_rejected) << r.label << "\n" << v.events;
  EXPECT_EQ(v.unexplained, 0) << r.label << "\n" << v.events;
  EXPECT_TRUE(test::honest(v)) << r.label << "\n" << v.events;
  return v;
}

TEST(PerturbationFamilies, AWhiteNoiseStatedLargerThanTheUnitsHidesNoBiasWander) {
  // Six gyros whose white noise is 0.69 times the stated (variance 0.48) and bias instability 1.63 times, a
  // 1 Hz reference, gyro 5 stepped at 53 s: the parity block match judged each 30-s block mean against the
  // stated white noise (the model never goes below it), 2.1 times the unit's in variance, which hid the
  // wander's excess: no match in the run, per-axis NEES 1.73 1.95 0.85 against the twin's 1.63 1.67 0.62,
  // and over 20 other draws of the noise its largest per-axis NEES +0.21 ± 0.05 above the twin's (charged).
  // The spread's verdict below the stated is now kept (ParitySpread::measured) and the block match's white
  // part predicted with it: matched (a noise_model event) at 594 s in this draw, earlier in others, and over
  // the 20 draws no longer worse than the twin. This draw's figures barely move (the match comes late): the
  // check is the match, and the run honest. Run of the sweep (seed 3): noisy-unit #267.
  const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kNoisyUnit, 3, 267);
  const test::FamilyVerdict v = expect_named_and_honest(r);
  EXPECT_FALSE(v.wrong_exclusion) << r.label << "\n" << v.events;
}

TEST(PerturbationFamilies, AUnitNoisierThanStatedInWhiteNoiseIsTrustedNoBetterInItsBiasTerms) {
  // Four gyros whose white noise is 1.64 times the stated and bias instability 2.99 times, a 1 Hz reference,
  // no fault: the parity's spread named the white noise at 7.6 s (a noise_model event: taken as 4.2 times its
  // stated variance), but the filter kept the stated bias terms, which the parity block match, judging 30-s
  // means of innovations the filter's own parity updates keep small, did not reject in 600 s: per-axis NEES
  // 2.66 1.24 1.20 against the twin's 1.52 0.97 0.92 (charged over 20 draws of the noise). A unit shown
  // noisier than its noise: section in one term is now trusted no better in the others until their data
  // (Mekf::set_bias_model_ratio): NEES 1.94 1.12 0.97. Run of the sweep (seed 5): noisy-unit #194.
  const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kNoisyUnit, 5, 194);
  const test::FamilyVerdict v = expect_named_and_honest(r);
  EXPECT_FALSE(v.exclusion_no_fault) << r.label << "\n" << v.events;
}

TEST(PerturbationFamilies, AFaultsAngleErrorTurnsWithTheBodyInSigma) {
  // Four gyros without a reference, gyro 1 reading zero from 35.3 s in a 36-deg slew about -X and back:
  // isolated at 36.2 s, the 0.9 s in between left 3,570 / 130 / 9,140 arcsec of error on body X / Y / Z,
  // which the isolation put into sigma as a bound on those axes. The slew then turned the Z error into Y
  // (3,640 arcsec there from 80 s on) while the bound stayed on Z: Y's sigma 2,425 arcsec, per-axis NEES
  // 1.49 2.09 0.34 against the twin's 0.00 (charged over 20 draws, the same in the noisy-unit family). The
  // bound now turns with the body (AttitudePropagator): NEES 0.48 0.22 0.28. Run of the sweep (seed 11):
  // calibration-without-noise #57.
  const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kCalibrationWithoutNoise, 11, 57);
  const test::FamilyVerdict v = judged(r);
  EXPECT_TRUE(test::honest(v)) << r.label << "\n" << v.events;
  EXPECT_LT(v.nees.maxCoeff(), 1.0) << r.label;  // 2.09 before; the bound is a bound, so well below 1
  EXPECT_FALSE(v.wrong_exclusion) << r.label << "\n" << v.events;
}

TEST(PerturbationFamilies, AWarmUpThatGoesOnAfterItsMatchKeepsTheHealthyReference) {
  // Four gyros warming from -4.9 to 20 degC (tau 321 s, -1.85e-6 deg/s/K common: 4.6e-5 deg/s at the start)
  // with a healthy 1 Hz star tracker: the common drift matched at 74 s, the model opened to 55 times its
  // wander, and the drift, at its fastest early in the transient, went on. A mean within
  // reference_bias_window_s of a match was taken as the reference's whatever it needed, so the tracker was
  // rejected at 101 s (its mean needing 4,022 times the wander, a working unit's). A mean that goes on now
  // asks for rho times more at each match and is the reference's only beyond 1e4 (docs/fdi.md, "A common
  // drift below the detectors"): the tracker kept. Run of the sweep (seed 3): warm-up #250.
  expect_tracker_kept_and_honest(sim::perturbed_run(sim::Family::kWarmUp, 3, 250));
}

TEST(PerturbationFamilies, AWarmUpsMeanJustAfterItsMatchIsJudgedSinceTheDriftWasFirstSeen) {
  // Four gyros warming from -0.3 to 20 degC (tau 475 s, -1.79e-6 deg/s/K common) with a healthy 1 Hz star
  // tracker: the drift matched at 74 s (the model opened to 52.6 times its wander), and 21 s into the next
  // bias block the filter still carried part of the error: that mean, taken as grown within those 21 s,
  // needed 10,772 times the wander (beyond 1e4, a working unit's), and the tracker was rejected at 95 s for
  // the rest of the run (per-axis NEES 0.22 0.02 0.02: sigma from the gyros alone). While matches persist the
  // mean is now judged over the time since the drift was first seen: matched again, the tracker kept, NEES
  // 1.01 0.74 0.68. Run of the sweep (seed 7): warm-up #251.
  expect_tracker_kept_and_honest(sim::perturbed_run(sim::Family::kWarmUp, 7, 251));
}

TEST(PerturbationFamilies, AReferenceRampTakenForACommonDriftIsInSigma) {
  // Four gyros, a 1 Hz star tracker whose own bias ramps by 10.3 arcsec over 29.8 s from 118 s: the mean
  // innovation matched as a common drift of the gyros at 170 s (a noise_model event; the data cannot tell the
  // two), the reference kept and followed. The protection level carried the reference's pull, sigma did not:
  // 49.2 % within 3 sigma, per-axis NEES 10.85 8.58 8.39 against the twin's 0.83 0.86 1.29 (charged over 20
  // draws). Sigma now covers Href too (docs/fdi.md, "A common drift below the detectors"): 100 % within 3
  // sigma, NEES 0.47 0.45 0.50. Run of the sweep (seed 17): reference #63.
  const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kReference, 17, 63);
  const test::FamilyVerdict v = expect_named_and_honest(r);
  EXPECT_GE(v.within, test::kMinWithin3Sigma) << r.label << "\n" << v.events;
  EXPECT_LE(v.nees.maxCoeff(), test::kMaxNeesPerAxis) << r.label << "\n" << v.events;
}

TEST(PerturbationFamilies, AWarmUpsRampThatTheStepTestFindsKeepsTheHealthyReference) {
  // Five gyros warming from -4.5 to 20 degC (tau 481 s, -1.18e-6 deg/s/K common) with a healthy 1 Hz star
  // tracker: at 72 s the reference's step test failed (53.9 against 53.3) before the bias test's mean reached
  // the drift match's level, and a step was taken as the reference's alone (a drift "shows as a mean
  // first"): rejected for the rest of the run, NEES 0.39 0.03 0.01 (sigma from the gyros). The step is now
  // judged against the best ramp, the shape a drift makes (drift_shape: χ²_step − χ²_ramp = −2.2, the ramp
  // fits better): matched as the drift, the tracker kept; sigma covers Href beside it (a reference's own ramp
  // has the same shape), NEES 0.33 0.01 0.01. Run of the sweep (seed 11): warm-up #255.
  const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kWarmUp, 11, 255);
  const test::FamilyVerdict v = expect_tracker_kept_and_honest(r);
  EXPECT_FALSE(v.wrong_exclusion) << r.label << "\n" << v.events;
}

TEST(PerturbationFamilies, AGyroStuckAtASlewsStartIsCoveredWhileTheJumpTestHoldsAnotherOut) {
  // Four gyros with the reference, a gyro stuck at the start of an agile slew: with one parity every
  // single-gyro hypothesis explains the jump, the motion judged possible (at the configured bound, below the
  // slew's) picked a healthy gyro, which the jump test left out while the stuck one went on in a solution
  // with no parity of its own, unchecked, for 0.7 s, until its repeated values isolated it. The error grew to
  // 285″ under a sigma of 1″ and a protection level of 7″ (NEES 21.4, |e|/PL 41.8 over the run). Sigma now
  // carries the rate error of every hypothesis over those epochs (docs/fdi.md, "One-epoch jump test"):
  // honest over the whole run, within the protection level wherever no alarm stands. Runs of the sweep
  // (seed 1): fault-in-slew #63, calibration #189 (|e|/PL 8.4 before), calibration-without-noise #27, #81
  // (6.0, 13.6).
  const std::vector<std::pair<sim::Family, std::uint64_t>> runs = {
      {sim::Family::kFaultInSlew, 63},
      {sim::Family::kCalibration, 189},
      {sim::Family::kCalibrationWithoutNoise, 27},
      {sim::Family::kCalibrationWithoutNoise, 81}};
  for (const auto& [family, index] : runs) {
    const sim::PerturbedRun r = sim::perturbed_run(family, 1, index);
    const test::FamilyVerdict v = test::judge_run(r);
    EXPECT_TRUE(test::honest(v)) << r.label << "\n" << v.events;
    EXPECT_EQ(v.beyond_protection, 0) << r.label << ": |e|/PL " << v.worst_protection_ratio;
  }
}

TEST(PerturbationFamilies, AReferenceRampIsInTheProtectionLevelBeforeItsDriftMatch) {
  // A star tracker's bias ramping by 13-16" over 47-57 s is, to the data, a common drift of the gyros: the
  // drift match keeps the reference and the protection level carries the reference's pull from the match
  // on; in the 3-4 s before it the error stood above the level (|e|/PL 1.09-1.11), the bias block's mean
  // already beyond a good reference's. The level now carries the pull a match would learn while that mean
  // is undecided (docs/fdi.md, "A common drift below the detectors"). Runs of the sweep (seed 3):
  // reference #23 (35 axis-epochs beyond it before, 159-163 s), #78 (21, 139-142 s).
  for (const std::uint64_t index : {23u, 78u}) {
    const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kReference, 3, index);
    const test::FamilyVerdict v = test::judge_run(r);
    EXPECT_EQ(v.wrong_exclusion, false) << r.label;
    EXPECT_EQ(v.beyond_protection, 0) << r.label << ": |e|/PL " << v.worst_protection_ratio << " ("
                                      << v.beyond_from_s << "-" << v.beyond_until_s << " s)";
  }
}

TEST(PerturbationFamilies, AWarmingUnitIsInTheProtectionLevelBeforeItsDriftMatch) {
  // Every gyro's bias following a warm-up (1.4-1.9e-6 deg/s/K over 12-25 K) with a healthy 1 Hz tracker: the
  // attitude error grows to 6-9" under a sigma of 0.8" before the drift match has the mean it needs (the
  // bias block's mean still below a good reference's), |e|/PL 1.04-1.19 for 3-20 s. The level now carries
  // Hdrift: the error the used samples' innovations show, their weighted mean over reference_window_s
  // (docs/fdi.md, "A common drift below the detectors"). Runs of the sweep (seed 3): warm-up #37, #44,
  // #250, #253 (1.05, 1.19, 1.12, 1.04 before); their twins' |e|/PL stays below 0.5.
  for (const std::uint64_t index : {37u, 44u, 250u, 253u}) {
    const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kWarmUp, 3, index);
    const test::FamilyVerdict v = test::judge_run(r);
    EXPECT_EQ(v.wrong_exclusion, false) << r.label;
    EXPECT_EQ(v.beyond_protection, 0) << r.label << ": |e|/PL " << v.worst_protection_ratio << " ("
                                      << v.beyond_from_s << "-" << v.beyond_until_s << " s)";
  }
}

TEST(PerturbationFamilies, AWarmingUnitsSigmaCarriesWhatTheReferenceShowsBeforeItsDriftMatch) {
  // The same with no event at all: the error 2-3" for 100-150 s under a sigma of 0.8", per-axis NEES 2.27,
  // 2.11, 2.47 over the run (twins 1.11-1.17), nothing flagged. Sigma now carries what the innovations' mean
  // shows beyond it (docs/fdi.md, "A common drift below the detectors"): 1.67, 1.63, 1.81; the bound 2 is the
  // sweep's per-run criterion. Runs of the sweep (seed 3): warm-up #38, #199, #209.
  for (const std::uint64_t index : {38u, 199u, 209u}) {
    const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kWarmUp, 3, index);
    const test::FamilyVerdict v = test::judge_run(r);
    EXPECT_FALSE(v.wrong_exclusion) << r.label;
    EXPECT_LE(v.nees.maxCoeff(), test::kMaxNeesPerAxis) << r.label << ": NEES " << v.nees.transpose();
  }
}

TEST(PerturbationFamilies, NoSlopeIsTakenAcrossAnIsolation) {
  // Four gyros and the reference, a gyro's output 0 V in mid-slew (3-4 deg/s): the isolation epoch's rate is
  // the three healthy gyros', the one before it all four's; the next step's curvature correction took the
  // slope between the two sets (the fault itself, tens of deg/s²) and put 70-80" into the attitude under a
  // sigma of 5": worst 14-19 sigma, per-axis NEES 2.51, 3.05, 3.18, charged against the twins. A slope across
  // an exclusion is now not taken (docs/fdi.md, "Per epoch" 7): NEES below 1.2 on every axis; the
  // worst, 6.7-7.5 sigma, is the fault's own error in its first epochs, before the episode's bound has the
  // parity (bound 10). Runs of the sweep (seed 3): fault-in-slew #67, calibration-without-noise #30,
  // noisy-unit #30.
  for (const auto& [family, index] :
       {std::pair{sim::Family::kFaultInSlew, 67u}, std::pair{sim::Family::kCalibrationWithoutNoise, 30u},
        std::pair{sim::Family::kNoisyUnit, 30u}}) {
    const sim::PerturbedRun r = sim::perturbed_run(family, 3, index);
    const test::FamilyVerdict v = test::judge_run(r);
    EXPECT_FALSE(v.wrong_exclusion) << r.label;
    EXPECT_LE(v.nees.maxCoeff(), test::kMaxNeesPerAxis) << r.label << ": NEES " << v.nees.transpose();
    EXPECT_LT(v.worst_sigmas, 10.0) << r.label;
  }
}

TEST(PerturbationFamilies, TheFirstRateAfterALostOneIsNotTheHeldOne) {
  // Four or five gyros with the reference, 7–20 % of samples dropped in an agile slew: an epoch with two
  // samples holds the rate; the next step's trapezoid took the held rate as its start, a slew's a·τ off, and
  // left 30–80″ under a sigma of 5″ (|e|/PL 1.2–2.9; 15 of the family's 300 runs). The step now takes the
  // previous rate on the line between the last measured one and the new one (docs/fdi.md, "Data path"): the
  // error within the protection level. Runs of the sweep (seed 1): data-path #255, #273, #297 (1.72, 1.69,
  // 1.22 before; #297 without jitter).
  for (const std::uint64_t index : {255u, 273u, 297u}) {
    const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kDataPath, 1, index);
    const test::FamilyVerdict v = test::judge_run(r);
    EXPECT_EQ(v.beyond_protection, 0) << r.label << ": |e|/PL " << v.worst_protection_ratio;
    EXPECT_LT(v.worst_sigmas, 5.0) << r.label;
  }
}

TEST(PerturbationFamilies, AHealthyReferenceRejectedOnADataSheetUnitIsUsedAgainOnceTheMismatchIsNamed) {
  // A data-sheet calibration (scale factors 14–30 % off, biases off): the second star-tracker sample, 1 s in,
  // disagrees with the gyros' attitude by 8σ, and the reference is rejected — the gyros vouch, nothing yet
  // says their calibration is wrong. Once the motion fit names the mismatch (600 s: two 300-s blocks), Hcal
  // explains the disagreement as well as Href: the rejection is judged again, and the reference is used
  // (before: left out for the rest of the run, the attitude 4–6° off under a sigma of hundreds of degrees).
  // Runs of the sweep (seed 3): data-sheet #86, #193 (N = 4), #92 (N = 5).
  for (const std::uint64_t index : {86u, 92u, 193u}) {
    const sim::PerturbedRun r = sim::perturbed_run(sim::Family::kDataSheet, 3, index);
    test::CampaignOptions options;
    options.keep_errors = true;
    fdi::PipelineConfig config;  // as the sweep runs it (family_campaign.hpp, judge_run)
    if (r.sample_period_s > 0.0) config.sample_period_s = r.sample_period_s;
    if (r.max_angular_acceleration_dps2 > 0.0)
      config.max_angular_acceleration_dps2 = r.max_angular_acceleration_dps2;
    const test::CampaignRun run = test::run_campaign(r.scenario, r.options, r.calibration, config, options);
    std::optional<double> rejected_s;
    std::optional<double> named_s;
    std::optional<double> used_again_s;
    bool hcal_row = false;
    for (const auto& e : run.events) {
      const double t = ns_to_seconds(e.stamp_ns);
      if (e.type == fdi::EventType::kReferenceRejected && !rejected_s) rejected_s = t;
      if (e.type == fdi::EventType::kCalibrationMismatch && !named_s) named_s = t;
      if (e.type != fdi::EventType::kReferenceAccepted || used_again_s) continue;
      used_again_s = t;
      for (const fdi::LedgerRow& row : e.ledger)
        hcal_row |=
            row.hypothesis == fdi::kHypothesisCalibration && row.verdict == fdi::RowVerdict::kConsistent;
    }
    ASSERT_TRUE(rejected_s && named_s && used_again_s) << r.label;
    EXPECT_LT(*rejected_s, 3.0) << r.label;
    EXPECT_EQ(*used_again_s, *named_s) << r.label;
    EXPECT_TRUE(hcal_row) << r.label;
    // From then on the attitude is the reference's, but in the slews (whose scale error sigma does not cover:
    // the event says so): the median error over the last 300 s within 4 × the tracker's 5″, against > 3,600″
    // (1°) while it was left out.
    std::vector<double> late_arcsec;
    for (std::size_t k = 0; k < run.time_s.size(); ++k)
      if (run.time_s[k] >= run.time_s.back() - 300.0)
        late_arcsec.push_back(run.error_rad[k].cwiseAbs().maxCoeff() / kArcsecToRad);
    std::nth_element(late_arcsec.begin(), late_arcsec.begin() + late_arcsec.size() / 2, late_arcsec.end());
    EXPECT_LT(late_arcsec[late_arcsec.size() / 2], 20.0) << r.label;
  }
}

// One run of the sweep, its events and figures beside its twin's: TETRA_FAMILY_SHOW=family:seed:index (e.g.
// reference:3:197), to read why a run the sweep lists failed; skipped otherwise.
TEST(PerturbationFamilies, ShowOneRun) {
  const char* v = std::getenv("TETRA_FAMILY_SHOW");
  if (v == nullptr) GTEST_SKIP() << "TETRA_FAMILY_SHOW=family:seed:index selects a run";
  const std::string text(v);
  const auto a = text.find(':');
  const auto b = text.find(':', a + 1);
  ASSERT_TRUE(a != std::string::npos && b != std::string::npos) << "TETRA_FAMILY_SHOW: family:seed:index";
  const auto family = sim::family_from_name(text.substr(0, a));
  ASSERT_TRUE(family.has_value()) << "TETRA_FAMILY_SHOW: no family " << text.substr(0, a);
  const std::uint64_t seed = std::stoull(text.substr(a + 1, b - a - 1));
  const std::uint64_t index = std::stoull(text.substr(b + 1));
  const sim::PerturbedRun r = sim::perturbed_run(*family, seed, index);
  for (const bool twin : {false, true}) {
    const test::FamilyVerdict f = test::judge_run(twin ? sim::unperturbed_twin(r) : r);
    std::printf(
        "%s%s: within 3 sigma %.2f %%, NEES %.2f %.2f %.2f, worst %.1f sigma, >PL %d (|e|/PL %.2f; "
        "%.1f-%.1f s), flagged after %.1f s\n%s",
        twin ? "twin of " : "", r.label.c_str(), 100.0 * f.within, f.nees.x(), f.nees.y(), f.nees.z(),
        f.worst_sigmas, f.beyond_protection, f.worst_protection_ratio, f.beyond_from_s, f.beyond_until_s,
        f.flagged_after_s.value_or(-1.0), f.events.c_str());
  }
  // TETRA_FAMILY_TRACE=PATH: the perturbed run's every accepted epoch as CSV, to plot what the figures sum
  // up.
  if (const char* path = std::getenv("TETRA_FAMILY_TRACE")) {
    const test::CampaignRun run = test::run_family_member(r);
    std::FILE* out = std::fopen(path, "w");
    ASSERT_NE(out, nullptr) << path << ": " << std::strerror(errno);
    std::fprintf(out,
                 "time_s,ex_arcsec,ey_arcsec,ez_arcsec,sx_arcsec,sy_arcsec,sz_arcsec,plx_arcsec,ply_arcsec,"
                 "plz_arcsec,mode\n");
    for (std::size_t k = 0; k < run.time_s.size(); ++k) {
      const Eigen::Vector3d e = run.error_rad[k] / kArcsecToRad;
      const Eigen::Vector3d s = run.sigma_rad[k] / kArcsecToRad;
      const Eigen::Vector3d pl = run.protection_level_rad[k] / kArcsecToRad;
      std::fprintf(out, "%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%s\n", run.time_s[k], e.x(), e.y(),
                   e.z(), s.x(), s.y(), s.z(), pl.x(), pl.y(), pl.z(), fdi::to_string(run.mode[k]));
    }
    ASSERT_EQ(std::fclose(out), 0) << path;
  }
}

}  // namespace
}  // namespace tetra
