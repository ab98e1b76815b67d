// Two small stages on their own: the gyro set's latched exclusions and the epoch time check
// (stamp_judge.hpp).
#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

#include "gyro_set.hpp"
#include "stamp_judge.hpp"
#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {
namespace {

TEST(GyroSet, ExclusionsAreLatchedUntilReinstated) {
  GyroSet set(4);
  EXPECT_EQ(set.active(), 0b1111U);
  set.exclude(2, FaultKind::kStuck);
  EXPECT_EQ(set.active(), 0b1101U);
  EXPECT_EQ(set.kind(2), FaultKind::kStuck);
  EXPECT_TRUE(set.is_excluded(2));
  EXPECT_FALSE(set.contains(5));
  set.reinstate(2);
  EXPECT_EQ(set.active(), 0b1111U);
  EXPECT_EQ(set.kind(2), FaultKind::kNone);
}

// The epoch time check: 10 ms period, so the window is 1000 periods = 10 s.
constexpr std::int64_t kJudgePeriod_ns = 10'000'000;

StampJudge judge_at(std::int64_t start_ns) {
  StampJudge j;
  j.set_period(kJudgePeriod_ns);
  EXPECT_EQ(j.judge(start_ns), StampVerdict::kAccepted);
  return j;
}

TEST(StampJudge, AStampFarAheadOrBehindIsAnOutlierAndNeverMovesTheTime) {
  StampJudge j = judge_at(0);
  for (const std::int64_t glitch :
       {std::int64_t{1'000'000} * kNanosPerSecond, -std::int64_t{1'000'000} * kNanosPerSecond,
        std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min()}) {
    EXPECT_EQ(j.judge(glitch), StampVerdict::kOutlier) << glitch;
  }
  EXPECT_EQ(*j.last_ns(), 0);
  EXPECT_EQ(j.judge(kJudgePeriod_ns), StampVerdict::kAccepted);
}

TEST(StampJudge, DuplicatesAndSmallStepsBackAreNotIncreasing) {
  StampJudge j = judge_at(0);
  EXPECT_EQ(j.judge(kJudgePeriod_ns), StampVerdict::kAccepted);
  EXPECT_EQ(j.judge(kJudgePeriod_ns), StampVerdict::kNotIncreasing);
  EXPECT_EQ(j.judge(kJudgePeriod_ns / 2), StampVerdict::kNotIncreasing);
  // The window's edge: 1000 periods ahead is accepted (a gap), 1000 periods back is not increasing.
  EXPECT_EQ(j.judge(1001 * kJudgePeriod_ns), StampVerdict::kAccepted);
  EXPECT_EQ(j.judge(kJudgePeriod_ns), StampVerdict::kNotIncreasing);
  EXPECT_EQ(j.judge(kJudgePeriod_ns - 1), StampVerdict::kOutlier);
}

TEST(StampJudge, AForwardJumpIsFollowedAfterThreeAgreeingStamps) {
  StampJudge j = judge_at(0);
  const std::int64_t jump = 100 * kNanosPerSecond;
  EXPECT_EQ(j.judge(jump), StampVerdict::kOutlier);
  EXPECT_EQ(j.judge(jump + kJudgePeriod_ns), StampVerdict::kOutlier);
  EXPECT_EQ(j.judge(jump + 2 * kJudgePeriod_ns), StampVerdict::kAccepted);
  EXPECT_EQ(*j.last_ns(), jump + 2 * kJudgePeriod_ns);
  EXPECT_EQ(j.judge(0), StampVerdict::kOutlier);  // the old time is now far behind
}

TEST(StampJudge, OutliersInterleavedWithGoodStampsNeverConfirmAJump) {
  StampJudge j = judge_at(0);
  for (int k = 1; k <= 10; ++k) {
    EXPECT_EQ(j.judge(100 * kNanosPerSecond + k * kJudgePeriod_ns), StampVerdict::kOutlier) << k;
    EXPECT_EQ(j.judge(k * kJudgePeriod_ns), StampVerdict::kAccepted) << k;
  }
}

TEST(StampJudge, WithoutAPeriodOnlyTheOrderIsJudged) {
  StampJudge j;
  EXPECT_EQ(j.judge(0), StampVerdict::kAccepted);
  EXPECT_EQ(j.judge(1'000'000 * kNanosPerSecond), StampVerdict::kAccepted);
  EXPECT_EQ(j.judge(0), StampVerdict::kNotIncreasing);
  j.reset();
  EXPECT_EQ(j.judge(0), StampVerdict::kAccepted);
}

}  // namespace
}  // namespace tetra::fdi::detail
