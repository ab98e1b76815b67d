// Small stages on their own: the gyro set's latched exclusions, the epoch time check (stamp_judge.hpp) and
// the reference innovations' weighted mean (innovation_mean.hpp).
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "gyro_set.hpp"
#include "innovation_mean.hpp"
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

TEST(InnovationMean, ItsVarianceIsWhatItsMeansShowAndItFollowsARampWithinItsLag) {
  // 1 Hz samples of a 5" noise, τ = 30 s: over 2,000 seeds of 300 samples the mean's spread per axis is its
  // stated variance within 10 % (the standard error of a variance from 2,000 values: 3 %); the stated
  // variance is the exact one of an exponentially weighted mean, S·(1 − λ)/(1 + λ) = S/60.5. Under a ramp
  // of r = 0.1"/s the mean lags the error by r·τ (3") within 0.3" once 10 τ have passed.
  const double tau_s = 30.0;
  const double sigma_rad = 5.0 * kArcsecToRad;
  const Eigen::Vector3d s_rad2 = Eigen::Vector3d::Constant(sigma_rad * sigma_rad);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  double sum_squares = 0.0;
  double stated = 0.0;
  const int seeds = 2000;
  for (int seed = 0; seed < seeds; ++seed) {
    InnovationMean mean(tau_s);
    EXPECT_TRUE(mean.empty());
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3d z(normal(rng), normal(rng), normal(rng));
      mean.add(k * 1'000'000'000LL, sigma_rad * z, s_rad2);
    }
    sum_squares += mean.mean_rad().squaredNorm() / 3.0;
    stated = mean.variance_rad2()[0];
  }
  const double lambda = std::exp(-1.0 / tau_s);
  EXPECT_NEAR(stated, sigma_rad * sigma_rad * (1.0 - lambda) / (1.0 + lambda), 1e-3 * stated);
  EXPECT_NEAR(sum_squares / seeds / stated, 1.0, 0.10);
  InnovationMean ramp(tau_s);
  const double rate_rad_s = 0.1 * kArcsecToRad;
  for (int k = 0; k <= 300; ++k)
    ramp.add(k * 1'000'000'000LL, Eigen::Vector3d::Constant(rate_rad_s * k), s_rad2);
  EXPECT_NEAR((rate_rad_s * 300 - ramp.mean_rad()[0]) / kArcsecToRad, 3.0, 0.3);
  ramp.reset();
  EXPECT_TRUE(ramp.empty());
}

TEST(InnovationMean, ItsExcessIsTheErrorSigmaDoesNotCoverAndRarelyAnyOtherwise) {
  // 1 Hz samples of a 5" tracker, τ = 30 s, an honest filter σ of 0.8" per axis. An error of 3" on one axis
  // beyond what σ covers: |m|² is 9 + Σ var m on average, so the excess is about √(9 − Σ σ²) = 2.66"; over
  // 500 seeds its mean is taken within 0.3" (the square root of a noisy square lies 0.1-0.2" below; 2.48"
  // measured). An error σ covers (0.8" per axis, correlated over τ like a filter's): it shows in m, so an
  // excess stands where the error happens to be beyond σ — in 124 of 500 seeds, 0.29" on average; at most
  // 30 % and 0.4" (a sigma of 0.8" widened by at most 1.1× on average).
  const double tau_s = 30.0;
  const double tracker_rad = 5.0 * kArcsecToRad;
  const Eigen::Vector3d s_rad2 = Eigen::Vector3d::Constant(tracker_rad * tracker_rad);
  const Eigen::Vector3d sigma_rad = Eigen::Vector3d::Constant(0.8 * kArcsecToRad);
  std::mt19937_64 rng(12);
  std::normal_distribution<double> normal;
  const int seeds = 500;
  double shown = 0.0, honest = 0.0;
  int honest_with_excess = 0;
  const double rho = std::exp(-1.0 / tau_s);  // the honest error's correlation from one sample to the next
  for (int seed = 0; seed < seeds; ++seed) {
    InnovationMean off(tau_s), covered(tau_s);
    EXPECT_EQ(off.excess_rad(sigma_rad), 0.0);
    Eigen::Vector3d e(normal(rng), normal(rng), normal(rng));
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
      const Eigen::Vector3d w(normal(rng), normal(rng), normal(rng));
      e = rho * e + std::sqrt(1.0 - rho * rho) * w;
      off.add(k * 1'000'000'000LL, Eigen::Vector3d(3.0 * kArcsecToRad, 0.0, 0.0) + tracker_rad * v, s_rad2);
      covered.add(k * 1'000'000'000LL, sigma_rad.cwiseProduct(e) + tracker_rad * v, s_rad2);
    }
    shown += off.excess_rad(sigma_rad) / kArcsecToRad / seeds;
    honest += covered.excess_rad(sigma_rad) / kArcsecToRad / seeds;
    honest_with_excess += covered.excess_rad(sigma_rad) > 0.0 ? 1 : 0;
  }
  EXPECT_NEAR(shown, std::sqrt(9.0 - 3.0 * 0.64), 0.3);
  EXPECT_LE(honest_with_excess, 3 * seeds / 10);
  EXPECT_LT(honest, 0.4);
}

}  // namespace
}  // namespace tetra::fdi::detail
