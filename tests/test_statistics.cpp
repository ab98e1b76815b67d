// Confidence intervals of campaign rates (tetra/sim/statistics.hpp) against exact values computed
// independently by tests/statistics_reference.py (the binomial and Poisson sums in 60-digit decimals,
// solved by bisection; no incomplete beta or gamma function), and against published Garwood tables.

#include <gtest/gtest.h>

#include <cmath>

#include "tetra/sim/statistics.hpp"

namespace tetra::sim {
namespace {

// Relative tolerance 1e-9: the quantiles are bisected to adjacent doubles, so what remains is the
// error of I_x itself (lgamma's ~1e-15 relative error on arguments up to ~3e3, i.e. ~1e-12 absolute in
// the exponent of the front factor, and the continued fraction's 1e-16 stop) divided by the slope of
// the CDF; 1e-9 leaves three orders of magnitude of room and still catches any wrong formula (those are
// off by percent).
constexpr double kRel = 1e-9;

void expect_rel(double got, double want) {
  if (want == 0.0) {
    EXPECT_EQ(got, 0.0);
  } else {
    EXPECT_NEAR(got, want, kRel * std::abs(want)) << "want " << want;
  }
}

TEST(Statistics, RegularizedBetaMatchesTheBinomialTail) {
  expect_rel(regularized_beta(0.3, 2, 5), 0.57982500000000003);
  expect_rel(regularized_beta(0.9, 7, 3), 0.947027862);
  expect_rel(regularized_beta(1e-3, 1, 2995), 0.95003829660264361);
  expect_rel(regularized_beta(0.02, 18, 503), 0.019046468650773616);
  EXPECT_EQ(regularized_beta(0.0, 2, 3), 0.0);
  EXPECT_EQ(regularized_beta(1.0, 2, 3), 1.0);
  EXPECT_TRUE(std::isnan(regularized_beta(0.5, 0, 3)));  // outside the domain: NaN, no abort
}

TEST(Statistics, ClopperPearsonMatchesExactBinomialBounds) {
  struct Case {
    std::uint64_t k, n;
    double lower, upper;
  };
  for (const Case& c :
       {Case{0, 10, 0, 0.30849710781876077}, Case{3, 10, 0.066739511177734495, 0.6524528500599972},
        Case{10, 10, 0.69150289218123928, 1}, Case{5, 100, 0.016431879182052161, 0.11283491110546276},
        Case{0, 1000, 0, 0.0036820838968656712}, Case{17, 520, 0.01915753319572339, 0.05182865158347285},
        Case{1, 3000, 8.4392337175634131e-06, 0.001855799994491922}}) {
    SCOPED_TRACE("k " + std::to_string(c.k) + " of n " + std::to_string(c.n));
    const Interval i = clopper_pearson(c.k, c.n, 0.95);
    expect_rel(i.lower, c.lower);
    expect_rel(i.upper, c.upper);
  }
  expect_rel(clopper_pearson_upper(0, 2995, 0.95), 0.00099974442090114239);
  expect_rel(clopper_pearson_upper(2, 520, 0.95), 0.012057382316004044);
  // k = 0: the closed form 1 − (α/2)^(1/n).
  expect_rel(clopper_pearson(0, 10, 0.95).upper, 1.0 - std::pow(0.025, 0.1));
  EXPECT_TRUE(std::isnan(clopper_pearson(3, 2, 0.95).upper));  // k > n
  EXPECT_TRUE(std::isnan(clopper_pearson(1, 2, 1.0).upper));   // confidence outside (0, 1)
}

TEST(Statistics, GarwoodMatchesExactPoissonBoundsAndPublishedTables) {
  struct Case {
    std::uint64_t k;
    double lower, upper;
  };
  for (const Case& c :
       {Case{0, 0, 3.6888794541139354}, Case{1, 0.025317807984289897, 5.5716433909388972},
        Case{2, 0.24220927854396501, 7.22468766772396}, Case{10, 4.7953886961324343, 18.390356042017778},
        Case{50, 37.110963737461866, 65.918766664336815}}) {
    SCOPED_TRACE("k " + std::to_string(c.k));
    const Interval i = garwood(c.k, 0.95);
    expect_rel(i.lower, c.lower);
    expect_rel(i.upper, c.upper);
  }
  // Published (Garwood 1936; 4 significant digits): k = 0 → 3.689; k = 1 → 0.0253–5.572; k = 10
  // → 4.795–18.39.
  EXPECT_NEAR(garwood(0, 0.95).upper, 3.689, 5e-4);
  EXPECT_NEAR(garwood(1, 0.95).lower, 0.0253, 5e-5);
  EXPECT_NEAR(garwood(10, 0.95).upper, 18.39, 5e-3);
  // k = 0, one-sided: −ln(1 − c) exactly (the exponential law).
  expect_rel(garwood_upper(0, 0.95), -std::log(0.05));
}

TEST(Statistics, FurtherTrialsToDecideARequirement) {
  // 0 events: (1 − 1e-3)^n ≤ 0.05 first at n = ln 0.05 / ln 0.999 = 2994.2 → 2995 runs.
  EXPECT_EQ(further_trials_below(0, 0, 1e-3, 0.95), 2995u);
  EXPECT_EQ(further_trials_below(0, 1000, 1e-3, 0.95), 1995u);
  EXPECT_EQ(further_trials_below(0, 2995, 1e-3, 0.95), 0u);
  // Each answer is the first count that decides: one run fewer does not.
  const auto m = further_trials_below(2, 520, 1e-3, 0.95);
  ASSERT_TRUE(m);
  EXPECT_LT(clopper_pearson_upper(2, 520 + *m, 0.95), 1e-3);
  EXPECT_GE(clopper_pearson_upper(2, 520 + *m - 1, 0.95), 1e-3);
  const auto up = further_trials_above(90, 100, 0.9, 0.95);
  ASSERT_TRUE(up);
  EXPECT_GT(clopper_pearson_lower(90 + *up, 100 + *up, 0.95), 0.9);
  EXPECT_LE(clopper_pearson_lower(90 + *up - 1, 100 + *up - 1, 0.95), 0.9);
  EXPECT_FALSE(further_trials_above(1, 2, 1.0, 0.95));  // a rate above 1 can never be shown
}

}  // namespace
}  // namespace tetra::sim
