// Allan analysis: published reference values, χ² quantiles, seeded synthetic noise of known size,
// gaps, and the noise-term fit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <random>
#include <vector>

#include "tetra/core/allan.hpp"
#include "tetra/core/allan_stats.hpp"
#include "tetra/core/csv.hpp"

namespace tetra {
namespace {

using allan::AdevPoint;
using allan::AllanOptions;
using allan::AllanResult;

// ---- published reference data ----------------------------------------------------------------

// Riley's NBS14 data set (NIST SP 1065, §12.3 "Test suite"; NBS Monograph 140 Annex 8.E): nine
// frequency values at τ0 = 1 s. Stable32's overlapping Allan deviation: 91.22945 (τ = 1 s) and
// 85.95287 (τ = 2 s). The published values carry 7 significant digits (half a unit of the last digit
// is 5.5e-8 relative), so 1e-6 relative is a real check of the arithmetic.
TEST(AllanReference, Nbs14NinePoint) {
  const std::vector<double> y = {892, 809, 823, 798, 671, 644, 883, 903, 677};
  const std::vector<std::int64_t> m = {1, 2};
  const auto pts = allan::overlapping_avar(y, {}, 1.0, m);
  ASSERT_EQ(pts.size(), 2U);
  EXPECT_NEAR(std::sqrt(pts[0].avar), 91.22945, 91.22945 * 1e-6);
  EXPECT_NEAR(std::sqrt(pts[1].avar), 85.95287, 85.95287 * 1e-6);
  EXPECT_EQ(pts[0].terms, 8);  // N − 2m with N = 10 phase points
  EXPECT_EQ(pts[1].terms, 6);
}

// The 1000-point NBS14 set (NIST SP 1065 §12.3, Table 31; also Riley, "The calculation of time
// domain frequency stability"): n(i+1) = 16807·n(i) mod 2147483647, n(0) = 1234567890, y = n/2147483647.
// Published overlapping Allan deviations: 2.922319e-01 (τ = 1), 9.159953e-02 (τ = 10),
// 3.241343e-02 (τ = 100). 7 digits again: 1e-6 relative is above their rounding (≤ 1.7e-7).
TEST(AllanReference, Nbs14ThousandPoint) {
  std::vector<double> y(1000);
  std::int64_t n = 1234567890;
  for (double& v : y) {
    v = static_cast<double>(n) / 2147483647.0;
    n = (16807 * n) % 2147483647;
  }
  const std::vector<std::int64_t> m = {1, 10, 100};
  const auto pts = allan::overlapping_avar(y, {}, 1.0, m);
  ASSERT_EQ(pts.size(), 3U);
  EXPECT_NEAR(std::sqrt(pts[0].avar), 2.922319e-01, 2.922319e-01 * 1e-6);
  EXPECT_NEAR(std::sqrt(pts[1].avar), 9.159953e-02, 9.159953e-02 * 1e-6);
  EXPECT_NEAR(std::sqrt(pts[2].avar), 3.241343e-02, 3.241343e-02 * 1e-6);
}

// A large constant offset (raw volts) must not cost digits: the same data + 1e6 give the same ADEV
// to 1e-9 relative (the mean is removed before the cumulative sum).
TEST(AllanReference, OffsetInvariant) {
  std::vector<double> y = {892, 809, 823, 798, 671, 644, 883, 903, 677};
  const std::vector<std::int64_t> m = {1, 2, 3, 4};
  const auto a = allan::overlapping_avar(y, {}, 1.0, m);
  for (double& v : y) v += 1e6;
  const auto b = allan::overlapping_avar(y, {}, 1.0, m);
  for (std::size_t i = 0; i < m.size(); ++i) EXPECT_NEAR(b[i].avar, a[i].avar, a[i].avar * 1e-9) << m[i];
}

// ---- χ² quantiles ------------------------------------------------------------------------------

// Exact cases: with 2 degrees of freedom χ² is exponential, quantile −2 ln(1 − p); with 1 it is a
// squared normal, quantile = (z_{(1+p)/2})², z_0.975 = 1.959963984540054. Tabulated: χ²_0.95(10) =
// 18.307038053275146, χ²_0.05(10) = 3.940299136119259 (to the printed digits of standard tables).
TEST(AllanStats, Chi2QuantileKnownValues) {
  for (const double p : {1e-6, 0.01, 0.158655, 0.5, 0.841345, 0.99, 1 - 1e-9}) {
    EXPECT_NEAR(allan::chi2_quantile(p, 2.0), -2.0 * std::log1p(-p), 1e-12 * (1.0 - 2.0 * std::log1p(-p)))
        << p;
  }
  const double z = 1.959963984540054;
  EXPECT_NEAR(allan::chi2_quantile(0.95, 1.0), z * z, 1e-10);
  EXPECT_NEAR(allan::chi2_quantile(0.95, 10.0), 18.307038053275146, 1e-9);
  EXPECT_NEAR(allan::chi2_quantile(0.05, 10.0), 3.940299136119259, 1e-9);
  EXPECT_TRUE(std::isnan(allan::chi2_quantile(0.0, 3.0)));
  EXPECT_TRUE(std::isnan(allan::chi2_quantile(0.5, -1.0)));
}

// Round trip over fractional and large degrees of freedom: cdf(quantile(p)) = p.
TEST(AllanStats, Chi2QuantileInvertsCdf) {
  for (const double dof : {0.7, 1.0, 1.5, 3.3, 12.0, 99.5, 1e3, 1e5, 2e6}) {
    for (const double p : {0.001, 0.025, 0.158655, 0.5, 0.841345, 0.975, 0.999}) {
      const double x = allan::chi2_quantile(p, dof);
      // The prefactor x^a e^−x / Γ(a) loses about a·ε to cancellation: 1e-12 up to 1e3 degrees of
      // freedom, 1e-9 beyond (more than the confidence intervals need).
      EXPECT_NEAR(allan::chi2_cdf(x, dof), p, dof <= 1e3 ? 1e-12 : 1e-9) << "dof " << dof << " p " << p;
    }
  }
}

// ---- synthetic data ----------------------------------------------------------------------------

struct Synth {
  double tau0_s = 0.01;
  std::size_t n = 0;
  double arw = 0.0;     // N [unit·√s]: white rate σ = N/√τ0
  double rrw = 0.0;     // K [unit/√s]: rate random walk, increment σ = K·√τ0
  double quant = 0.0;   // angle quantization step q; Q = q/√12
  double ramp = 0.0;    // R [unit/s]
  double offset = 0.0;  // constant rate
  std::uint64_t seed = 1;
};

// Angle quantization is modelled as a dithered quantizer produces it: an independent angle error,
// uniform over one step q, on each sample's angle (white angle noise, Q = q/√12, IEEE 952 C.2).
std::vector<double> synthesize(const Synth& s) {
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-0.5, 0.5);
  std::vector<double> y(s.n);
  double walk = 0.0;
  double angle_error = s.quant * uniform(rng);
  for (std::size_t i = 0; i < s.n; ++i) {
    const double t = static_cast<double>(i) * s.tau0_s;
    walk += s.rrw * std::sqrt(s.tau0_s) * gauss(rng);
    double rate = s.offset + s.ramp * t + walk + s.arw / std::sqrt(s.tau0_s) * gauss(rng);
    if (s.quant > 0.0) {
      const double next_error = s.quant * uniform(rng);
      rate += (next_error - angle_error) / s.tau0_s;
      angle_error = next_error;
    }
    y[i] = rate;
  }
  return y;
}

AllanResult analyze(const std::vector<double>& y, double tau0_s,
                    const std::vector<std::uint8_t>& present = {}) {
  auto r = allan::analyze_series(y, present, tau0_s, AllanOptions{});
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? r.value() : AllanResult{};
}

// Least-squares slope of log ADEV against log τ over tau_lo ≤ τ ≤ tau_hi.
double slope(const AllanResult& r, double tau_lo, double tau_hi) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int k = 0;
  for (const AdevPoint& p : r.points) {
    if (p.tau_s < tau_lo || p.tau_s > tau_hi) continue;
    const double x = std::log10(p.tau_s);
    const double yv = std::log10(p.adev);
    sx += x;
    sy += yv;
    sxx += x * x;
    sxy += x * yv;
    ++k;
  }
  EXPECT_GE(k, 5) << "too few points for a slope";
  return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

// White rate noise N = 3e-5 deg/√s (seed Table 6 level) at 100 Hz for 20 min: N within 5 % (the
// estimate's own scatter over 120 000 samples is about 0.5 %), slope −½ over 0.1–10 s within ±0.05,
// and Q, K, R not observed.
TEST(AllanSynthetic, WhiteRateNoiseGivesN) {
  Synth s;
  s.n = 120000;
  s.arw = 3e-5;
  s.offset = 4e-3;  // Earth-rate-sized constant: must not matter
  s.seed = 11;
  const AllanResult r = analyze(synthesize(s), s.tau0_s);
  ASSERT_TRUE(r.fit.reported(allan::kN).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kN), 3e-5, 0.05 * 3e-5);
  EXPECT_NEAR(slope(r, 0.1, 10.0), -0.5, 0.05);
  EXPECT_FALSE(r.fit.reported(allan::kQ).has_value());
  EXPECT_FALSE(r.fit.reported(allan::kK).has_value());
  EXPECT_FALSE(r.fit.reported(allan::kR).has_value());
}

// Rate random walk K = 2e-6 /√s with white noise N = 1e-5 √s (crossing at τ = √3·N/K ≈ 9 s), 1 Hz
// for 20 000 s: K within 25 % (its estimate rests on the few long-τ points), N within 10 %, slope +½
// over 200–5000 s within ±0.15.
TEST(AllanSynthetic, RateRandomWalkGivesK) {
  Synth s;
  s.tau0_s = 1.0;
  s.n = 20000;
  s.arw = 1e-5;
  s.rrw = 2e-6;
  s.seed = 7;
  const AllanResult r = analyze(synthesize(s), s.tau0_s);
  ASSERT_TRUE(r.fit.reported(allan::kK).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kK), 2e-6, 0.25 * 2e-6);
  ASSERT_TRUE(r.fit.reported(allan::kN).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kN), 1e-5, 0.10 * 1e-5);
  EXPECT_NEAR(slope(r, 200.0, 5000.0), 0.5, 0.15);
}

// Angle quantization q = 1e-3 deg (Q = q/√12) with a little white rate noise: Q within 5 %, slope −1
// over 0.01–1 s within ±0.05.
TEST(AllanSynthetic, QuantizationGivesQ) {
  Synth s;
  s.n = 60000;
  s.quant = 1e-3;
  s.offset = 0.37;
  s.arw = 1e-7;
  s.seed = 5;
  const AllanResult r = analyze(synthesize(s), s.tau0_s);
  ASSERT_TRUE(r.fit.reported(allan::kQ).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kQ), 1e-3 / std::sqrt(12.0), 0.05 * 1e-3 / std::sqrt(12.0));
  EXPECT_NEAR(slope(r, 0.01, 1.0), -1.0, 0.05);
}

// A rate ramp R = 1e-5 /s² under white noise: slope +1 at long τ (±0.1), R within 10 %
// (deterministic, so well determined), N still within 5 %.
TEST(AllanSynthetic, RateRampGivesSlopePlusOne) {
  Synth s;
  s.tau0_s = 0.1;
  s.n = 36000;
  s.arw = 1e-4;
  s.ramp = 1e-5;
  s.seed = 3;
  const AllanResult r = analyze(synthesize(s), s.tau0_s);
  ASSERT_TRUE(r.fit.reported(allan::kR).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kR), 1e-5, 0.10 * 1e-5);
  ASSERT_TRUE(r.fit.reported(allan::kN).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kN), 1e-4, 0.05 * 1e-4);
  EXPECT_NEAR(slope(r, 300.0, 1800.0), 1.0, 0.1);
}

// Flicker rate noise by Kasdin's fractional-integration filter (h_0 = 1, h_k = h_{k−1}(k − ½)/k) on
// white innovations of σ = 1e-5: one-sided PSD 2σ²τ0/(2 sin πfτ0) ≈ σ²/(πf), so h₋₁ = σ²/π and the
// flat Allan variance 2 ln2·h₋₁ = (2 ln2/π)σ², i.e. B = σ in IEEE 952's σ² = (2 ln2/π)B². Checks:
// slope 0 within ±0.1 over 1–100 s; B within 10 % of 1e-5 (10 seeds scatter ±4 %); B alone observed.
TEST(AllanSynthetic, FlickerRateGivesFlatFloor) {
  const std::size_t n = 12000;
  std::mt19937_64 rng(17);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<double> w(n);
  for (double& v : w) v = gauss(rng);
  std::vector<double> h(n);
  h[0] = 1.0;
  for (std::size_t k = 1; k < n; ++k)
    h[k] = h[k - 1] * (static_cast<double>(k) - 0.5) / static_cast<double>(k);
  std::vector<double> y(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    double acc = 0.0;
    for (std::size_t k = 0; k <= i; ++k) acc += h[k] * w[i - k];
    y[i] = 1e-5 * acc;
  }
  const AllanResult r = analyze(y, 0.1);
  EXPECT_NEAR(slope(r, 1.0, 100.0), 0.0, 0.1);
  ASSERT_TRUE(r.fit.reported(allan::kB).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kB), 1e-5, 0.10 * 1e-5);
  EXPECT_FALSE(r.fit.reported(allan::kN).has_value());
  EXPECT_FALSE(r.fit.reported(allan::kK).has_value());
}

// Combined Q + N + K at the seed's scale, 100 Hz for one hour: each slope where its term dominates,
// N within 5 %, K within 25 %, Q within 15 % (Q and N overlap at the shortest τ).
TEST(AllanSynthetic, CombinedTermsAndSlopes) {
  Synth s;
  s.n = 360000;
  s.arw = 3e-5;
  s.rrw = 2e-5;
  s.quant = 2e-5;
  s.offset = 0.05;
  s.seed = 23;
  const AllanResult r = analyze(synthesize(s), s.tau0_s);
  ASSERT_TRUE(r.fit.reported(allan::kN).has_value());
  ASSERT_TRUE(r.fit.reported(allan::kK).has_value());
  ASSERT_TRUE(r.fit.reported(allan::kQ).has_value());
  EXPECT_NEAR(*r.fit.reported(allan::kN), 3e-5, 0.05 * 3e-5);
  EXPECT_NEAR(*r.fit.reported(allan::kK), 2e-5, 0.25 * 2e-5);
  EXPECT_NEAR(*r.fit.reported(allan::kQ), 2e-5 / std::sqrt(12.0), 0.15 * 2e-5 / std::sqrt(12.0));
  EXPECT_NEAR(slope(r, 0.3, 3.0), -0.5, 0.1);
  EXPECT_NEAR(slope(r, 100.0, 1000.0), 0.5, 0.2);
}

// ---- gaps --------------------------------------------------------------------------------------

// Gap handling against the definition: with random gaps, the O(n) cumulative-sum result equals a
// brute-force average over every window whose 2m samples are all present (to 1e-9 relative —
// summation order only).
TEST(AllanGaps, MatchesBruteForceDefinition) {
  Synth s;
  s.tau0_s = 1.0;
  s.n = 400;
  s.arw = 1.0;
  s.rrw = 0.05;
  s.seed = 99;
  const std::vector<double> y = synthesize(s);
  std::mt19937_64 rng(4);
  std::vector<std::uint8_t> present(y.size(), 1);
  for (std::size_t i = 0; i < y.size(); ++i) present[i] = (rng() % 10 == 0) ? 0 : 1;
  const std::vector<std::int64_t> ms = {1, 2, 3, 5, 8};
  const auto pts = allan::overlapping_avar(y, present, 1.0, ms);
  for (std::size_t j = 0; j < ms.size(); ++j) {
    const auto m = static_cast<std::size_t>(ms[j]);
    double sum = 0.0;
    std::int64_t terms = 0;
    for (std::size_t i = 0; i + 2 * m <= y.size(); ++i) {
      bool all = true;
      double a = 0.0, b = 0.0;
      for (std::size_t k = 0; k < m; ++k) {
        all = all && present[i + k] && present[i + m + k];
        a += y[i + k];
        b += y[i + m + k];
      }
      if (!all) continue;
      const double d = (b - a) / static_cast<double>(m);
      sum += 0.5 * d * d;
      ++terms;
    }
    ASSERT_EQ(pts[j].terms, terms) << "m " << m;
    EXPECT_NEAR(pts[j].avar, sum / static_cast<double>(terms), 1e-9 * pts[j].avar) << "m " << m;
  }
}

// A log with gaps (5 % of samples lost in bursts of 1–50) gives the same curve as the gap-free log:
// at every τ where the gapped log keeps at least 10 degrees of freedom (a burst every ~5 s leaves
// few gap-free windows of 10 s and more), the gap-free ADEV lies inside the gapped log's 95 %
// interval (95 % rather than 68 %: ~30 correlated points are compared; the two estimates share 95 %
// of their data, so a miss at 95 % means a real bias), and N agrees within 5 %.
TEST(AllanGaps, GappedLogAgreesWithinConfidence) {
  Synth s;
  s.n = 100000;
  s.arw = 3e-5;
  s.rrw = 1e-5;
  s.seed = 31;
  const std::vector<double> y = synthesize(s);
  std::vector<std::uint8_t> present(y.size(), 1);
  std::mt19937_64 rng(8);
  std::size_t lost = 0;
  while (lost < y.size() / 20) {
    const std::size_t start = rng() % y.size();
    const std::size_t len = 1 + rng() % 50;
    for (std::size_t i = start; i < std::min(y.size(), start + len); ++i) {
      lost += present[i];
      present[i] = 0;
    }
  }
  const AllanResult full = analyze(y, s.tau0_s);
  AllanOptions opt;
  opt.confidence = 0.95;
  auto gapped_r = allan::analyze_series(y, present, s.tau0_s, opt);
  ASSERT_TRUE(gapped_r.ok());
  const AllanResult& gapped = *gapped_r;
  ASSERT_EQ(gapped.present_samples, y.size() - lost);
  std::size_t compared = 0;
  for (const AdevPoint& g : gapped.points) {
    if (g.edf < 10.0) continue;  // the gapped log no longer tells much there
    for (const AdevPoint& f : full.points) {
      if (f.tau_s != g.tau_s) continue;
      EXPECT_GE(f.adev, g.adev_lo) << "tau " << g.tau_s;
      EXPECT_LE(f.adev, g.adev_hi) << "tau " << g.tau_s;
      ++compared;
    }
  }
  EXPECT_GT(compared, 20U);
  ASSERT_TRUE(gapped.fit.reported(allan::kN).has_value());
  EXPECT_NEAR(*gapped.fit.reported(allan::kN), *full.fit.reported(allan::kN), 0.05 * 3e-5);
}

// ---- confidence intervals ----------------------------------------------------------------------

// Coverage of the EDF/χ² intervals: over 400 independent white-noise series of 1000 samples, the
// 68.3 % interval at m = 10 contains the true ADEV (σ/√m for white rate noise) in 68.3 % of cases;
// with 400 trials the binomial 3σ band is ±7 %, so we require 61–76 %. A crude interval of the
// wrong width (e.g. 1/√terms, too narrow by ~2×) fails this.
TEST(AllanConfidence, WhiteNoiseCoverage) {
  int covered = 0;
  const int trials = 400;
  for (int t = 0; t < trials; ++t) {
    Synth s;
    s.tau0_s = 1.0;
    s.n = 1000;
    s.arw = 1.0;
    s.seed = 1000 + static_cast<std::uint64_t>(t);
    AllanOptions opt;
    opt.taus.spacing = allan::TauSpacing::kList;
    opt.taus.list_s = {1.0, 2.0, 5.0, 10.0, 20.0, 50.0};
    auto r = allan::analyze_series(synthesize(s), {}, 1.0, opt);
    ASSERT_TRUE(r.ok());
    for (const AdevPoint& p : r->points) {
      if (p.tau_s != 10.0) continue;
      const double truth = 1.0 / std::sqrt(10.0);
      covered += (p.adev_lo <= truth && truth <= p.adev_hi) ? 1 : 0;
    }
  }
  const double rate = static_cast<double>(covered) / trials;
  EXPECT_GT(rate, 0.61);
  EXPECT_LT(rate, 0.76);
}

// ---- τ sets and sampling -----------------------------------------------------------------------

TEST(AllanTaus, SpecsAndLimits) {
  auto spec = allan::parse_tau_spec("octave");
  ASSERT_TRUE(spec.ok());
  auto ms = allan::averaging_factors(*spec, 100, 0.01);
  ASSERT_TRUE(ms.ok());
  EXPECT_EQ(*ms, (std::vector<std::int64_t>{1, 2, 4, 8, 16, 32}));
  ms = allan::averaging_factors(*allan::parse_tau_spec("decade"), 1000, 1.0);
  EXPECT_EQ(*ms, (std::vector<std::int64_t>{1, 2, 5, 10, 20, 50, 100, 200, 500}));
  // Default: about ten per decade (the first decade has duplicates removed: 1,2,3,4,5,6,8).
  ms = allan::averaging_factors(*allan::parse_tau_spec(""), 200000, 0.01);
  EXPECT_EQ(ms->size(), 7U + 10U * 4U + 1U);  // up to m = 100000 = n/2
  // Lists round to whole multiples of τ0; out-of-range and non-positive times are errors.
  ms = allan::averaging_factors(*allan::parse_tau_spec("0.1, 1,1.004"), 1000, 0.01);
  EXPECT_EQ(*ms, (std::vector<std::int64_t>{10, 100}));
  EXPECT_FALSE(allan::parse_tau_spec("1,-2").ok());
  EXPECT_FALSE(allan::parse_tau_spec("1,abc").ok());
  EXPECT_FALSE(allan::averaging_factors(*allan::parse_tau_spec("0.001"), 1000, 0.01).ok());
  EXPECT_FALSE(allan::averaging_factors(*allan::parse_tau_spec("6"), 1000, 0.01).ok());
  EXPECT_FALSE(allan::averaging_factors(*allan::parse_tau_spec("all"), 2000000, 0.01).ok());
}

TEST(AllanSampling, MissingEpochsBecomeGapsAndJitterIsRefused) {
  const std::vector<double> t = {0.0, 0.01, 0.02, 0.05, 0.06, 0.0702};
  auto grid = allan::uniform_grid(t, 0.05, "log.csv");
  ASSERT_TRUE(grid.ok()) << grid.error().message;
  EXPECT_NEAR(grid->tau0_s, 0.0702 / 7.0, 1e-15);  // the mean step over the grid, not the median
  EXPECT_EQ(grid->missing_epochs, 2U);
  EXPECT_EQ(grid->slot, (std::vector<std::size_t>{0, 1, 2, 5, 6, 7}));
  const std::vector<double> bad = {0.0, 0.01, 0.02, 0.035, 0.045};
  const std::vector<std::size_t> lines = {2, 3, 4, 5, 6};
  auto r = allan::uniform_grid(bad, 0.05, "log.csv", lines);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("log.csv:5:"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("non-uniform"), std::string::npos) << r.error().message;
  EXPECT_FALSE(allan::uniform_grid(std::vector<double>{0.0}, 0.05, "log.csv").ok());
  EXPECT_FALSE(allan::uniform_grid(std::vector<double>{0.0, 0.01, 0.01}, 0.05, "log.csv").ok());
}

}  // namespace
}  // namespace tetra

namespace tetra {
namespace {

// The CSV reader parses large bodies (> 8 MB) in two halves on two threads; rows, line numbers,
// metadata order and the first error in file order must be exactly those of one pass.
TEST(CsvParallelParse, SameTableAndErrorsAsSequential) {
  std::string text = "# units=dps\ntime_s,g1,g2\n";
  const std::size_t rows = 300000;  // ~10 MB
  for (std::size_t i = 0; i < rows; ++i) {
    if (i == rows * 3 / 4) text += "# note=late\n";
    text += std::to_string(i) + ".25,0.001234567890123," + (i % 7 == 0 ? "" : "-2.5e-05") + "\n";
  }
  ASSERT_GT(text.size(), std::size_t{8} << 20);
  auto t = parse_csv(text, "big.csv");
  ASSERT_TRUE(t.ok()) << t.error().message;
  ASSERT_EQ(t->rows, rows);
  EXPECT_EQ(t->lines.front(), 3U);
  EXPECT_EQ(t->lines[rows * 3 / 4 - 1], rows * 3 / 4 - 1 + 3);
  EXPECT_EQ(t->lines[rows * 3 / 4], rows * 3 / 4 + 4);  // after the comment line
  EXPECT_EQ(t->lines.back(), rows + 3);
  EXPECT_DOUBLE_EQ(t->cell(rows - 1, 0), static_cast<double>(rows - 1) + 0.25);
  EXPECT_TRUE(t->is_empty(rows - 1 - (rows - 1) % 7, 2));
  EXPECT_EQ(t->meta("note"), std::optional<std::string>("late"));
  // An error deep in the second half names its own line.
  std::string bad = text;
  const std::string needle = "290000.25,0.001234567890123,-2.5e-05\n";
  const auto at = bad.find(needle);
  ASSERT_NE(at, std::string::npos);
  bad.replace(at, needle.size(), "290000.25,x,-2.5e-05\n");
  auto e = parse_csv(bad, "big.csv");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "big.csv:290004: column 'g1': 'x' is not a number");
  // Errors in both halves: the first in file order is reported.
  const std::string early = "10.25,0.001234567890123,-2.5e-05\n";
  bad.replace(bad.find(early), early.size(), "10.25,0.001234567890123\n");
  e = parse_csv(bad, "big.csv");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "big.csv:13: expected 3 fields as in the header, found 2");
}

}  // namespace
}  // namespace tetra
