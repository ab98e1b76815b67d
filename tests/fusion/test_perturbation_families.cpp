// The perturbation families' campaign (docs/fdi.md, "Perturbation families"): every family of
// sim/perturbation_families.hpp as its own seeded generator, a cheap subset in ctest (TETRA_FAMILY_RUNS runs
// per family, default below; TETRA_FAMILY_SEED the seed, default 1), the long sweep in
// bench/perturbation_sweep.sh. Asserted per family: no exclusion of a gyro without a fault begun, no
// exclusion in a fault-free run, never LOST from one fault, and every run's sigma honest (≥ 97 % of
// axis-epochs within 3σ, per-axis NEES ≤ 2). The figures are printed per family.
#include <cstdlib>
#include <map>
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

//! Runs `fallback` (or TETRA_FAMILY_RUNS) indices of `family`, prints its figures and each case's, returns
//! the family's.
test::FamilyFigures run_family(sim::Family family, std::uint64_t fallback) {
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
  for (const auto& [name, c] : cases) test::print_figures("  " + name, c);
  return f;
}

void expect_promises(const test::FamilyFigures& f) {
  EXPECT_EQ(f.wrong_exclusions, 0);
  EXPECT_EQ(f.exclusions_without_fault, 0);
  EXPECT_TRUE(f.failures.empty()) << f.failures;
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
// once or more; the bench runs hundreds per family.
TEST(PerturbationFamilies, FaultInSlew) {
  expect_promises(run_family(sim::Family::kFaultInSlew, 42));
}
TEST(PerturbationFamilies, DataPath) {
  expect_promises(run_family(sim::Family::kDataPath, 12));
}
TEST(PerturbationFamilies, Gap) {
  expect_promises(run_family(sim::Family::kGap, 18));
}
TEST(PerturbationFamilies, Reference) {
  expect_promises(run_family(sim::Family::kReference, 15));
}
TEST(PerturbationFamilies, Calibration) {
  expect_promises(run_family(sim::Family::kCalibration, 18));
}
TEST(PerturbationFamilies, CalibrationWithoutNoise) {
  expect_promises(run_family(sim::Family::kCalibrationWithoutNoise, 18));
}
TEST(PerturbationFamilies, SecondFault) {
  expect_promises(run_family(sim::Family::kSecondFault, 8));
}

}  // namespace
}  // namespace tetra
