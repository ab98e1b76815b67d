// The parity's own spread (fdi/src/parity_spread.hpp): the stated white noise rejected when, and only when,
// the parity's differences show another; the ratio taken covers the true one; a fall is followed back.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "parity_spread.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {
namespace {

constexpr double kP = 1e-9;  //!< the budget's share for the spread (p × 1 at the default p)

//! Successive differences of white parity vectors of variance `lambda` per axis, as the jump test forms
//! them: u_k = |p_k − p_{k−1}|²/2, χ²_d·λ with the lag-one dependence of the real statistic.
class Differences {
 public:
  Differences(int dof, std::uint64_t seed) : dof_(dof), rng_(seed), last_(static_cast<std::size_t>(dof)) {
    for (double& x : last_) x = normal_(rng_);
  }
  double next(double lambda) {
    double u = 0.0;
    for (double& x : last_) {
      const double now = std::sqrt(lambda) * normal_(rng_);
      u += (now - x) * (now - x) / 2.0;
      x = now;
    }
    return u;
  }

 private:
  int dof_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
  std::vector<double> last_;
};

TEST(ParitySpread, TheStatedNoiseIsNeverRejectedWhereItHolds) {
  // 3 dofs × 40 seeds × 25,000 samples = 3e6 looks at p = 1e-9 per look (times the window's length in the
  // threshold): not one verdict expected, none allowed.
  int verdicts = 0;
  for (int dof = 1; dof <= 3; ++dof) {
    const double cap = chi2_threshold(kP, dof);
    for (std::uint64_t seed = 1; seed <= 40; ++seed) {
      ParitySpread spread(kP);
      spread.reset();
      Differences diff(dof, seed * 7919 + static_cast<std::uint64_t>(dof));
      for (int k = 0; k < 25000; ++k) {
        if (spread.observe(diff.next(1.0), dof, cap, k * 100'000'000LL)) ++verdicts;
      }
      EXPECT_DOUBLE_EQ(spread.ratio(), 1.0);
      EXPECT_TRUE(spread.checked());
    }
  }
  EXPECT_EQ(verdicts, 0);
}

// The statistic as the pipeline forms it: relative to the model in use (the subsets are rebuilt on each
// verdict's ratio).
double relative(Differences& diff, double lambda, const ParitySpread& spread) {
  return diff.next(lambda) / spread.ratio();
}

TEST(ParitySpread, AUnitThreeTimesNoisierIsSeenWithinSecondsAndCovered) {
  // White noise 3× the stated (variance 9), d = 1, the jump threshold censoring 4 % of the samples: over 30
  // seeds the first verdict comes within 60 samples (6 s at 10 Hz), its ratio at least the truth less 30 %
  // (a 1σ upper end falls short one time in six; the next verdicts raise it) and at most 3 times it (the 1σ
  // upper end of an estimate from 20–40 samples); 3,000 samples later the ratio is within −20 %/+50 % of the
  // truth.
  const double cap = chi2_threshold(kP, 1);
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    ParitySpread spread(kP);
    spread.reset();
    Differences diff(1, seed);
    int at = -1;
    for (int k = 0; k < 200 && at < 0; ++k) {
      if (spread.observe(relative(diff, 9.0, spread), 1, cap, k * 100'000'000LL)) at = k;
    }
    ASSERT_GE(at, 0) << "seed " << seed;
    EXPECT_LE(at, 60) << "seed " << seed;
    EXPECT_GE(spread.ratio(), 0.7 * 9.0) << "seed " << seed;
    EXPECT_LE(spread.ratio(), 3.0 * 9.0) << "seed " << seed;
    for (int k = 0; k < 3000; ++k) (void)spread.observe(relative(diff, 9.0, spread), 1, cap, 0);
    EXPECT_GE(spread.ratio(), 0.8 * 9.0) << "seed " << seed;
    EXPECT_LE(spread.ratio(), 1.5 * 9.0) << "seed " << seed;
  }
}

TEST(ParitySpread, ASmallExcessIsSeenWithinAWindowAndAFallIsFollowedBack) {
  // Variance 1.5× (white noise 1.22×): seen within the 3,000-sample window in at least 18 of 20 seeds;
  // then the same unit at its stated noise again (a noisy gyro removed, N ≥ 5): the ratio comes back to
  // within 1.3 of the stated within 3,000 samples more, never below 1.
  const double cap = chi2_threshold(kP, 2);
  int seen = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    ParitySpread spread(kP);
    spread.reset();
    Differences diff(2, 1000 + seed);
    std::int64_t t = 0;
    for (int k = 0; k < 3000; ++k)
      (void)spread.observe(relative(diff, 1.5, spread), 2, cap, t += 100'000'000LL);
    if (spread.ratio() >= 1.3) ++seen;
    for (int k = 0; k < 6000; ++k)
      (void)spread.observe(relative(diff, 1.0, spread), 2, cap, t += 100'000'000LL);
    EXPECT_GE(spread.ratio(), 1.0);
    EXPECT_LE(spread.ratio(), 1.3) << "seed " << seed;
  }
  EXPECT_GE(seen, 18);
}

TEST(ParitySpread, AUnitQuieterThanStatedKeepsTheStatedModelAndSaysWhatItMeasured) {
  // Variance 0.48× the stated (white noise 0.69×, a data sheet's conservative figure), d = 1 and 2: the model
  // stays at the stated noise (ratio 1: a detector whitened with it keeps its budget), and within 3,000
  // samples measured() says what the data show: the upper end of a verdict's 1σ interval, so at least the
  // truth in about 84 % of the seeds (at least 14 of 20 required), never below it by more than 15 % (the
  // verdicts come after 100–300 samples: 1σ is 10–15 %), never above it by more than 30 %; the stated unit's
  // noise raised (another test) or a reset bring it back. Failed before measured() existed: the verdict was
  // dropped.
  for (int dof = 1; dof <= 2; ++dof) {
    int covered = 0;
    const double cap = chi2_threshold(kP, dof);
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      ParitySpread spread(kP);
      spread.reset();
      Differences diff(dof, 3000 + seed);
      std::int64_t t = 0;
      for (int k = 0; k < 3000; ++k) (void)spread.observe(diff.next(0.48), dof, cap, t += 100'000'000LL);
      EXPECT_DOUBLE_EQ(spread.ratio(), 1.0);
      if (spread.measured() >= 0.48) ++covered;
      EXPECT_GE(spread.measured(), 0.85 * 0.48) << "dof " << dof << " seed " << seed;
      EXPECT_LE(spread.measured(), 1.3 * 0.48) << "dof " << dof << " seed " << seed;
      spread.raise_to(2.0);
      EXPECT_DOUBLE_EQ(spread.measured(), 2.0);
      spread.reset();
      EXPECT_DOUBLE_EQ(spread.measured(), 1.0);
    }
    EXPECT_GE(covered, 14) << "dof " << dof;
  }
}

//! Whether an alarm of `statistic` against `threshold` decides: the arbiter over its detection row and, while
//! the model is unchecked, the spread's Hnoise row.
bool decides(const ParitySpread& spread, double statistic, double threshold, bool chi2) {
  std::vector<LedgerRow> rows{
      judge(EvidenceSource::kCusum, kHypothesisNone, statistic, threshold, threshold)};
  if (const auto noise = spread.noise_row(statistic, threshold, chi2)) {
    EXPECT_EQ(noise->hypothesis, kHypothesisNoise);
    EXPECT_EQ(noise->source, EvidenceSource::kUncheckedNoise);
    rows.push_back(*noise);
  }
  return arbitrate_detection(rows.data(), rows.data() + rows.size());
}

TEST(ParitySpread, AnAlarmTheUncheckedNoiseCouldExplainIsHeldAndALargerOneIsNot) {
  ParitySpread spread(kP);
  spread.reset();
  EXPECT_FALSE(spread.checked());
  // A χ² up to 16 times its threshold, a sum up to 4 times (the root), a white noise 16 times the model's
  // could explain: Hnoise stands, the alarm decides nothing yet.
  EXPECT_FALSE(decides(spread, 15.99 * 37.3, 37.3, true));
  EXPECT_TRUE(decides(spread, 16.01 * 37.3, 37.3, true));
  EXPECT_FALSE(decides(spread, 3.99 * 22.8, 22.8, false));
  EXPECT_TRUE(decides(spread, 4.01 * 22.8, 22.8, false));
  EXPECT_NEAR(spread.noise_row(2.0 * 22.8, 22.8, false)->statistic, 4.0, 1e-12);  // the variance ratio
  Differences diff(1, 5);
  for (int k = 0; k < design::spread_hold_samples; ++k) (void)spread.observe(diff.next(1.0), 1, 37.3, k);
  EXPECT_TRUE(spread.checked());
  EXPECT_FALSE(spread.noise_row(40.0, 37.3, true).has_value());  // checked: Hnoise is not written
  EXPECT_TRUE(decides(spread, 40.0, 37.3, true));
  // Without samples (three gyros, a body never within the bound) the check ends after design::spread_hold_s.
  ParitySpread idle(kP);
  idle.reset();
  (void)idle.observe(std::nan(""), 1, 37.3, 0);
  (void)idle.observe(std::nan(""), 1, 37.3, static_cast<std::int64_t>(design::spread_hold_s * 1e9));
  EXPECT_TRUE(idle.checked());
}

//! Whether a sum's alarm needing `needed` times the model's white noise variance decides against the long-run
//! spread's Hnoise row (`allowed_row`).
bool sum_decides(const ParitySpread& spread, double needed, double cap) {
  const double threshold = 22.8;
  const double statistic = std::sqrt(needed) * threshold;
  const std::vector<LedgerRow> rows{
      judge(EvidenceSource::kCusum, kHypothesisNone, statistic, threshold, threshold),
      spread.allowed_row(statistic, threshold, cap)};
  return arbitrate_detection(rows.data(), rows.data() + rows.size());
}

TEST(ParitySpread, AFewValuesBoundTheNoiseLooselyAndTheBoundCoversTheTruth) {
  // The long-run spread's Hnoise row stands up to the upper end of the estimate's 1σ interval. Values as the
  // block second differences give them (d = 1, the stated quantization's share q added), the unit's white
  // noise λ = 1 or 2 times the model's. Three values bound nothing: an alarm needing 1.43 × (a CUSUM 20 %
  // beyond its threshold) decides nothing, on every seed, whatever the three show. The bound covers the true
  // λ in at least 80 % of 400 seeds at every count from 2 to 19 values (one-sided 1σ: 84 % nominal; the count
  // below spread_min_samples, so no verdict moves the model). 2,000 values of λ = 1 bound it within 1.1: the
  // same alarm decides.
  const double cap = 1e9;  // no censoring: the moment estimate of the offset's case
  for (const double q : {0.0, 1.745}) {
    for (const double lambda : {1.0, 2.0}) {
      std::vector<int> covered(20, 0);
      for (std::uint64_t seed = 1; seed <= 400; ++seed) {
        ParitySpread spread(kP);
        spread.reset();
        Differences diff(1, 77 + seed);
        for (int n = 1; n < 20; ++n) {
          (void)spread.observe(diff.next(lambda) + q, 1, cap, n * 5'000'000'000LL, q);
          if (n == 3 && q > 0.0) {
            EXPECT_FALSE(sum_decides(spread, 1.43, cap)) << "seed " << seed;
          }
          if (n >= 2 && !sum_decides(spread, lambda, cap)) ++covered[static_cast<std::size_t>(n)];
        }
      }
      for (int n = 2; n < 20; ++n) {
        EXPECT_GE(covered[static_cast<std::size_t>(n)], 320)
            << "q " << q << " lambda " << lambda << " n " << n;
      }
    }
  }
  ParitySpread spread(kP);
  spread.reset();
  Differences diff(1, 3);
  for (int n = 1; n <= 2000; ++n) (void)spread.observe(diff.next(1.0) + 1.745, 1, cap, n, 1.745);
  EXPECT_DOUBLE_EQ(spread.ratio(), 1.0);  // no verdict
  EXPECT_TRUE(sum_decides(spread, 1.43, cap));
}

}  // namespace
}  // namespace tetra::fdi::detail
