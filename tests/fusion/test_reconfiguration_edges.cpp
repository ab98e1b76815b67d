// The edges of a reconfiguration (docs/fdi.md, "Reconfiguration and modes"): one gyro fault at the edges of
// an agile slew's motion — just before, at and just after its start and its end, and in its middle, each
// jittered over a second so every sample phase occurs — on four, five and six gyros, with and without the
// reference, both acceleration bounds, over many seeds. The promise checked: the published mode is never LOST
// at an epoch where three or more healthy gyros delivered samples that observe the rate (the fault's gyro is
// unhealthy from its onset on). The count checked is 0: a promise, not a rate. Before the gate's call was
// withdrawn at an isolation and the noise-level test waited for another gyro's repeats, 37 of 20,000 runs
// (seed 1) broke it, 3 of them among the first 2,000 that ctest runs (TETRA_EDGE_RUNS, TETRA_EDGE_SEED and
// TETRA_EDGE_FROM run others).
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "campaign.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/sim/perturbation_families.hpp"
#include "tetra/sim/random.hpp"

namespace tetra {
namespace {

constexpr double kAfter_s = 60.0;  //!< [s] the run goes on this long after the slew's end

double between(sim::Rng& rng, double lo, double hi) {
  return lo + (hi - lo) * rng.uniform();
}

//! Run `index` under `seed`: the `fault-in-slew` family's run (its fault kinds, N = 4, 5, 6, the reference or
//! not, both acceleration bounds, the slew of 30–45° in 10–15 s about ±X, ±Y or ±Z) with the fault moved to
//! an edge of the slew's motion — 1 s before, at or 0.5 s after its start, its middle, 1 s or 0.5 s before or
//! at its end — plus up to one second, so every sample phase occurs; it ends kAfter_s after the slew.
sim::PerturbedRun edge_run(std::uint64_t seed, std::uint64_t index) {
  sim::PerturbedRun r = sim::perturbed_run(sim::Family::kFaultInSlew, seed, index);
  sim::Rng rng(sim::splitmix64(sim::splitmix64(seed) ^ (index + 1)));
  const sim::Slew& slew = r.scenario.motion.slews.front();
  const double start = slew.start_s;
  const double end = slew.start_s + slew.duration_s;
  const double edges[] = {start - 1.0, start, start + 0.5, 0.5 * (start + end), end - 1.0, end - 0.5, end};
  auto& f = r.options.faults.front();
  f.at_s = edges[static_cast<int>(rng.uniform() * 7) % 7] + between(rng, 0.0, 1.0);
  r.scenario.duration_s = end + kAfter_s;
  r.label += ", moved to " + std::to_string(f.at_s) + " s";
  return r;
}

//! Epochs published LOST while three or more healthy gyros delivered an observable rate.
struct LostCount {
  int runs = 0;
  int runs_with_lost = 0;
  int lost_epochs = 0;
  std::string failures;
};

void count_lost(const sim::PerturbedRun& r, LostCount& count) {
  fdi::PipelineConfig config;
  config.max_angular_acceleration_dps2 = r.max_angular_acceleration_dps2;
  test::CampaignOptions options;
  options.keep_errors = true;
  const test::CampaignRun run = test::run_campaign(r.scenario, r.options, r.calibration, config, options);
  auto geometry = GyroGeometry::create(r.scenario.unit.axes_B());
  ASSERT_TRUE(geometry.ok());
  const auto& f = r.options.faults.front();
  int lost = 0;
  std::string first;
  for (std::size_t k = 0; k < run.time_s.size(); ++k) {
    GyroMask healthy = run.delivered[k];
    if (run.time_s[k] >= f.at_s) healthy = without_gyro(healthy, f.gyro);
    if (run.mode[k] != fdi::Mode::kLost || !geometry->observable(healthy)) continue;
    if (lost++ == 0) first = std::to_string(run.time_s[k]);
  }
  ++count.runs;
  if (lost == 0) return;
  ++count.runs_with_lost;
  count.lost_epochs += lost;
  count.failures += r.label + ": " + std::to_string(lost) + " LOST epochs, first at " + first + " s\n" +
                    test::describe(run, r.scenario.unit.gyro_count());
}

TEST(ReconfigurationEdges, NeverLostWhileThreeHealthyGyrosDeliver) {
  LostCount count;
  const char* env = std::getenv("TETRA_EDGE_RUNS");
  const std::uint64_t runs = env != nullptr ? std::strtoull(env, nullptr, 10) : 2000;
  const char* from_env = std::getenv("TETRA_EDGE_FROM");
  const std::uint64_t from = from_env != nullptr ? std::strtoull(from_env, nullptr, 10) : 0;
  const char* seed_env = std::getenv("TETRA_EDGE_SEED");
  const std::uint64_t seed = seed_env != nullptr ? std::strtoull(seed_env, nullptr, 10) : 1;
  for (std::uint64_t i = from; i < from + runs; ++i) count_lost(edge_run(seed, i), count);
  std::printf("runs %d, with LOST while three healthy gyros delivered %d, LOST epochs %d\n", count.runs,
              count.runs_with_lost, count.lost_epochs);
  EXPECT_EQ(count.lost_epochs, 0) << count.failures;
}

}  // namespace
}  // namespace tetra
