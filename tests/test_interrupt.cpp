// tetra::Interrupt: the long library calls poll their caller and stop when it asks (the Python package's
// Ctrl-C and progress, docs/python.md), with nothing left behind.
#include "tetra/core/interrupt.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "tetra/core/allan.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra {
namespace {

TEST(Interrupt, TheSimulatorStopsAtThePollThatAsksAndKeepsNoTruth) {
  sim::Scenario sc = sim::builtin_scenario("static").value();
  sc.duration_s = 600.0;
  std::vector<std::size_t> polls;
  std::size_t total = 0;
  Interrupt interrupt([&](std::size_t done, std::size_t all) {
    polls.push_back(done);
    total = all;
    return done >= 1000;
  });
  sim::Truth truth;
  const auto log = sim::simulate_log(sc, {}, &truth, &interrupt);
  ASSERT_FALSE(log);
  EXPECT_EQ(describe(log.error()), "interrupted");
  EXPECT_TRUE(interrupt.stopped());
  EXPECT_TRUE(truth.time_s.empty());
  EXPECT_EQ(polls.back(), 1024u);  // every 64 epochs: the first poll at or past 1000
  EXPECT_EQ(total, static_cast<std::size_t>(std::llround(sc.duration_s * sc.rate_hz)));
  // Never asked to stop: the same run as without an interrupt.
  Interrupt never([](std::size_t, std::size_t) { return false; });
  const auto whole = sim::simulate_log(sc, {}, nullptr, &never);
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->values, sim::simulate_log(sc, {}).value().values);
}

TEST(Interrupt, AllanStopsBetweenAveragingTimes) {
  std::vector<double> rate(20000);
  for (std::size_t i = 0; i < rate.size(); ++i) rate[i] = std::sin(0.37 * static_cast<double>(i));
  allan::AllanOptions options;
  std::size_t asked = 0;
  Interrupt interrupt([&](std::size_t done, std::size_t) {
    ++asked;
    return done == 3;
  });
  options.interrupt = &interrupt;
  const auto r = allan::analyze_series(rate, {}, 0.1, options);
  ASSERT_FALSE(r);
  EXPECT_EQ(describe(r.error()), "interrupted");
  EXPECT_EQ(asked, 4u);
  options.interrupt = nullptr;
  EXPECT_TRUE(allan::analyze_series(rate, {}, 0.1, options));
}

TEST(Interrupt, ACampaignRunStopsWithinItsEpochs) {
  const auto spec = sim::parse_campaign_spec(
      "scenarios: [static]\nloop: open\nduration_s: 600\nkinds: [bias]\nsizes: {bias: [0.01]}\n"
      "gyros: [1]\nonsets_s: [300]\nseeds: [1]\n",
      "spec", ".");
  ASSERT_TRUE(spec) << describe(spec.error());
  std::size_t last = 0;
  Interrupt interrupt([&](std::size_t done, std::size_t) {
    last = done;
    return done >= 10;
  });
  const sim::CampaignRow row = sim::campaign_run_row(*spec, 0, sim::in_process_estimators(*spec), &interrupt);
  EXPECT_EQ(row.error, "interrupted");
  EXPECT_EQ(last, 10u);  // polled every epoch
  EXPECT_TRUE(sim::campaign_run_row(*spec, 0, sim::in_process_estimators(*spec)).error.empty());
}

}  // namespace
}  // namespace tetra
