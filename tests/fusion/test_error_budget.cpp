// The error budget the configuration implies (docs/fdi.md, "The budget"): its sums are the rows', its
// false-alarm total is the figure docs/fdi.md states for the defaults at 10 Hz, and each row moves with its
// key.
#include <array>
#include <cmath>

#include <gtest/gtest.h>

#include "tetra/fdi/budget.hpp"

namespace tetra::fdi {
namespace {

TEST(ErrorBudget, DefaultsAt10HzGiveTheDocumentedFalseAlarmRate) {
  const Budget b = error_budget(PipelineConfig{}, 4, 0.1);
  // χ² 1e-9 and CUSUM 1/1e8 per epoch at 36,000 epochs per hour: 0.396 per 1,000 h (docs/fdi.md: 0.40).
  EXPECT_NEAR(b.false_alarms_per_hour * 1000.0, 0.396, 1e-9);
  double sum = 0.0;
  for (const BudgetRow& r : b.rows)
    if (r.kind == BudgetKind::kWrongExclusion && std::isfinite(r.per_evaluation)) sum += r.total();
  EXPECT_DOUBLE_EQ(b.wrong_exclusion_per_episode, sum);
  EXPECT_GT(b.wrong_exclusion_per_episode, 0.0);
  EXPECT_LT(b.wrong_exclusion_per_episode,
            1e-4);  // onset 5σ (5.7e-7) x 30 evaluations, the windows' 6σ cubed
}

TEST(ErrorBudget, TheGltRowAppearsFromFiveGyrosAndFollowsItsKey) {
  PipelineConfig c;
  const auto glt = [](const Budget& b) {
    for (const BudgetRow& r : b.rows)
      if (std::string(r.source) == "glt") return r.total();
    return -1.0;
  };
  EXPECT_EQ(glt(error_budget(c, 4, 0.1)), -1.0);
  const double base = glt(error_budget(c, 5, 0.1));
  EXPECT_NEAR(base, 2e-9 * 50.0, 1e-18);  // two forms, per epoch of the 5 s isolation window at 10 Hz
  c.false_alarm_probability = 1e-6;
  EXPECT_NEAR(glt(error_budget(c, 5, 0.1)), 2e-6 * 50.0, 1e-15);
  c.sample_period_s = 0.01;
  EXPECT_NEAR(error_budget(c, 6, 0.01).false_alarms_per_hour,
              10.0 * error_budget(c, 6, 0.1).false_alarms_per_hour,
              1e-12);  // per epoch: ten times the epochs, ten times the alarms
}

TEST(ErrorBudget, EveryProbabilityIsItsShareOfTheOneKey) {
  // One key, one table of shares: doubling false_alarm_probability doubles every test's probability and the
  // false-alarm total; the CUSUM's in-control ARL is 1/(10 p): 1e8 epochs at the default 1e-9.
  PipelineConfig c;
  EXPECT_DOUBLE_EQ(cusum_arl0_epochs(c), 1e8);
  EXPECT_DOUBLE_EQ(allocated_probability(c, BudgetTest::kReferenceGate), 1e-6);
  const double total = error_budget(c, 4, 0.1).false_alarms_per_hour;
  std::array<double, kBudgetTestCount> before{};
  for (int t = 0; t < kBudgetTestCount; ++t) {
    EXPECT_EQ(static_cast<int>(kAllocations[t].test), t) << kAllocations[t].name;  // the table's order
    EXPECT_GT(kAllocations[t].share, 0.0);
    EXPECT_LE(kAllocations[t].share, kLargestShare);
    before[static_cast<std::size_t>(t)] = allocated_probability(c, kAllocations[t].test);
  }
  c.false_alarm_probability *= 2.0;
  for (int t = 0; t < kBudgetTestCount; ++t)
    EXPECT_DOUBLE_EQ(allocated_probability(c, kAllocations[t].test),
                     2.0 * before[static_cast<std::size_t>(t)]);
  EXPECT_DOUBLE_EQ(error_budget(c, 4, 0.1).false_alarms_per_hour, 2.0 * total);
  // The key's range keeps the largest share a test: p below 0.5 / 1000.
  c.false_alarm_probability = 0.5 / kLargestShare;
  EXPECT_FALSE(validate(c).ok());
}

TEST(ErrorBudget, TheTestsThatDecideNothingTakeTheLargestShareAndAreListed) {
  // The parity block match opens bias models and decides nothing, as the reference bias match, the motion fit
  // and the parity's spread: each takes the largest share (1e-6 at the default p). The block match's row is
  // Wald's bound for the first of |S| gyros' CUSUMs, p·|S|² per epoch: 1.6e-5 for four gyros, 5.76e-1 per
  // hour at 10 Hz; it is a noise-model row, not a false alarm.
  const PipelineConfig c;
  for (const BudgetTest t : {BudgetTest::kParityBlockMatch, BudgetTest::kReferenceBiasMatch,
                             BudgetTest::kMotionFit, BudgetTest::kParitySpread, BudgetTest::kReferenceGate})
    EXPECT_DOUBLE_EQ(allocated_probability(c, t), 1e-6) << kAllocations[static_cast<int>(t)].name;
  const Budget b = error_budget(c, 4, 0.1);
  int rows = 0;
  for (const BudgetRow& r : b.rows) {
    if (std::string(r.source) != "parity_block_match") continue;
    ++rows;
    EXPECT_EQ(r.kind, BudgetKind::kNoiseModel);
    EXPECT_NEAR(r.per_evaluation, 1.6e-5, 1e-18);
    EXPECT_NEAR(r.total(), 0.576, 1e-12);
  }
  EXPECT_EQ(rows, 1);
  EXPECT_NEAR(b.false_alarms_per_hour * 1000.0, 0.396, 1e-9);  // not in the false alarms
}

TEST(ErrorBudget, SignaturesAreListedWithoutAFigure) {
  const Budget b = error_budget(PipelineConfig{}, 5, 0.1);
  int unbudgeted = 0;
  for (const BudgetRow& r : b.rows) unbudgeted += std::isfinite(r.per_evaluation) ? 0 : 1;
  EXPECT_EQ(unbudgeted, 5);
  const std::string text = to_text(b);
  EXPECT_NE(text.find("not a probability"), std::string::npos);
  EXPECT_NE(text.find("false alarms per 1,000 h"), std::string::npos);
}

}  // namespace
}  // namespace tetra::fdi
