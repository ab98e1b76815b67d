// The perturbation families' campaign (docs/fdi.md, "Perturbation families"): every family of
// sim/perturbation_families.hpp as its own seeded generator, a cheap subset in ctest (TETRA_FAMILY_RUNS runs
// per family, default below; TETRA_FAMILY_SEED the seed, default 1), the long sweep in
// bench/perturbation_sweep.sh. Asserted per family: no exclusion of a gyro without a fault begun, no
// exclusion in a fault-free run, never LOST from one fault, and every run's sigma honest (≥ 97 % of
// axis-epochs within 3σ, per-axis NEES ≤ 2). The figures are printed per family.
#include <cstdlib>
#include <map>
#include <set>
#include <string>

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
  for (std::uint64_t i = 0; i < runs; ++i) {
    const sim::PerturbedRun r = sim::perturbed_run(family, seed, i);
    // With three gyros (redundancy exhausted) or two faults, an exclusion leaves the rate unobservable.
    const bool lost_allowed = r.scenario.unit.gyro_count() - 1 < 3 || r.options.faults.size() > 1;
    const test::FamilyVerdict v = test::judge_run(r);
    const test::FamilyVerdict twin = test::judge_run(sim::unperturbed_twin(r));
    test::add_run(f, r, v, twin, lost_allowed);
    test::add_run(cases[r.case_name], r, v, twin, lost_allowed);
  }
  test::print_figures_header();
  test::print_figures(std::string(sim::family_name(family)), f);
  for (const auto& [name, c] : cases)
    test::print_figures("  " + name + (limits.count(name) ? " (limit)" : ""), c);
  for (const auto& [name, c] : cases) {
    EXPECT_EQ(c.wrong_exclusions, 0) << name << "\n" << c.failures;
    EXPECT_EQ(c.exclusions_without_fault, 0) << name << "\n" << c.failures;
    EXPECT_EQ(c.lost_from_one_fault, 0) << name << "\n" << c.failures;
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
// A reference bias of 10–40″ (step or ramp) that the filter follows within its noise is not always caught,
// and a late reference at a steady rate is an offset: docs/fdi.md, "Reference consistency", Limits. The
// protection level bounds gyro faults: it takes the reference samples it anchors on as true.
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
// reference's innovations, and each is covered from then on (docs/fdi.md, "Perturbation families").
// The protection level bounds one gyro fault: two that cancel in the parity are beyond it.
TEST(PerturbationFamilies, SecondFault) {
  check_family(sim::Family::kSecondFault, 12, {}, {"two biases cancelling in the parity"});
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

}  // namespace
}  // namespace tetra
