#include "tetra/sim/statistics.hpp"

#include <cmath>
#include <limits>

#include "tetra/core/allan_stats.hpp"

namespace tetra::sim {

namespace {

constexpr double kNaNStat = std::numeric_limits<double>::quiet_NaN();
constexpr double kTinyStat = 1e-300;           // keeps Lentz's denominators off zero
constexpr double kEpsStat = 1e-16;             // a continued fraction or series has converged
constexpr int kMaxStatIterations = 1'000'000;  // far beyond what a campaign's counts need

//! The continued fraction of I_x(a, b) (modified Lentz), valid for x < (a + 1)/(a + b + 2).
double beta_fraction(double x, double a, double b) {
  double c = 1.0;
  double d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < kTinyStat) d = kTinyStat;
  d = 1.0 / d;
  double f = d;
  for (int m = 1; m <= kMaxStatIterations; ++m) {
    const double dm = static_cast<double>(m);
    // Even step: m(b − m)x / ((a + 2m − 1)(a + 2m)).
    double term = dm * (b - dm) * x / ((a + 2.0 * dm - 1.0) * (a + 2.0 * dm));
    d = 1.0 + term * d;
    c = 1.0 + term / c;
    if (std::abs(d) < kTinyStat) d = kTinyStat;
    if (std::abs(c) < kTinyStat) c = kTinyStat;
    d = 1.0 / d;
    f *= d * c;
    // Odd step: −(a + m)(a + b + m)x / ((a + 2m)(a + 2m + 1)).
    term = -(a + dm) * (a + b + dm) * x / ((a + 2.0 * dm) * (a + 2.0 * dm + 1.0));
    d = 1.0 + term * d;
    c = 1.0 + term / c;
    if (std::abs(d) < kTinyStat) d = kTinyStat;
    if (std::abs(c) < kTinyStat) c = kTinyStat;
    d = 1.0 / d;
    const double delta = d * c;
    f *= delta;
    if (std::abs(delta - 1.0) < kEpsStat) return f;
  }
  return kNaNStat;
}

//! x in [lo, hi] with cdf(x) = p for an increasing cdf, bisected until lo and hi are adjacent doubles.
template <class Cdf>
double bisect(Cdf cdf, double p, double lo, double hi) {
  for (int i = 0; i < 4000; ++i) {
    const double mid = lo + 0.5 * (hi - lo);
    if (mid <= lo || mid >= hi) break;
    const double v = cdf(mid);
    if (std::isnan(v)) return kNaNStat;
    (v < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

bool valid_confidence(double confidence) {
  return confidence > 0.0 && confidence < 1.0;
}

//! The fewest m ≥ 0 (up to kMaxFurtherTrials) with done(m) true, for done false then true as m grows.
template <class Done>
std::optional<std::uint64_t> first_true(Done done) {
  if (done(0)) return std::uint64_t{0};
  std::uint64_t lo = 0;  // done(lo) false
  std::uint64_t hi = 1;
  while (!done(hi)) {
    lo = hi;
    if (hi >= kMaxFurtherTrials) return std::nullopt;
    hi = std::min(hi * 2, kMaxFurtherTrials);
  }
  while (hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    (done(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace

double regularized_beta(double x, double a, double b) {
  if (!(a > 0.0) || !(b > 0.0) || std::isnan(x)) return kNaNStat;
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double log_front =
      std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  if (x < (a + 1.0) / (a + b + 2.0)) return std::exp(log_front) * beta_fraction(x, a, b) / a;
  return 1.0 - std::exp(log_front) * beta_fraction(1.0 - x, b, a) / b;
}

double beta_quantile(double p, double a, double b) {
  if (!(a > 0.0) || !(b > 0.0) || !(p >= 0.0 && p <= 1.0)) return kNaNStat;
  if (p == 0.0) return 0.0;
  if (p == 1.0) return 1.0;
  return bisect([&](double x) { return regularized_beta(x, a, b); }, p, 0.0, 1.0);
}

double gamma_quantile(double p, double a) {
  if (!(a > 0.0) || !(p >= 0.0 && p < 1.0)) return kNaNStat;
  if (p == 0.0) return 0.0;
  return 0.5 * allan::chi2_quantile(p, 2.0 * a);  // Gamma(a, 1) is χ²(2a)/2
}

double clopper_pearson_upper(std::uint64_t k, std::uint64_t n, double confidence) {
  if (n == 0 || k > n || !valid_confidence(confidence)) return kNaNStat;
  if (k == n) return 1.0;
  return beta_quantile(confidence, static_cast<double>(k) + 1.0, static_cast<double>(n - k));
}

double clopper_pearson_lower(std::uint64_t k, std::uint64_t n, double confidence) {
  if (n == 0 || k > n || !valid_confidence(confidence)) return kNaNStat;
  if (k == 0) return 0.0;
  return beta_quantile(1.0 - confidence, static_cast<double>(k), static_cast<double>(n - k) + 1.0);
}

Interval clopper_pearson(std::uint64_t k, std::uint64_t n, double confidence) {
  if (!valid_confidence(confidence)) return {kNaNStat, kNaNStat};
  const double one_sided = 1.0 - 0.5 * (1.0 - confidence);
  return {clopper_pearson_lower(k, n, one_sided), clopper_pearson_upper(k, n, one_sided)};
}

double garwood_upper(std::uint64_t k, double confidence) {
  if (!valid_confidence(confidence)) return kNaNStat;
  return gamma_quantile(confidence, static_cast<double>(k) + 1.0);
}

double garwood_lower(std::uint64_t k, double confidence) {
  if (!valid_confidence(confidence)) return kNaNStat;
  if (k == 0) return 0.0;
  return gamma_quantile(1.0 - confidence, static_cast<double>(k));
}

Interval garwood(std::uint64_t k, double confidence) {
  if (!valid_confidence(confidence)) return {kNaNStat, kNaNStat};
  const double one_sided = 1.0 - 0.5 * (1.0 - confidence);
  return {garwood_lower(k, one_sided), garwood_upper(k, one_sided)};
}

// upper(k, N) < bound ⟺ I_bound(k + 1, N − k) > confidence (I_x increases with x): one evaluation of
// the incomplete beta per candidate, no quantile.
std::optional<std::uint64_t> further_trials_below(std::uint64_t k, std::uint64_t n, double bound,
                                                  double confidence) {
  if (!(bound > 0.0) || k > n || !valid_confidence(confidence)) return std::nullopt;
  if (bound >= 1.0) return k < n ? std::optional<std::uint64_t>(0) : std::optional<std::uint64_t>(1);
  return first_true([&](std::uint64_t m) {
    const std::uint64_t total = n + m;
    if (total <= k) return false;
    return regularized_beta(bound, static_cast<double>(k) + 1.0, static_cast<double>(total - k)) > confidence;
  });
}

// lower(k', N') > bound ⟺ I_bound(k', N' − k' + 1) < 1 − confidence.
std::optional<std::uint64_t> further_trials_above(std::uint64_t k, std::uint64_t n, double bound,
                                                  double confidence) {
  if (!(bound < 1.0) || k > n || !valid_confidence(confidence)) return std::nullopt;
  if (bound < 0.0) return std::uint64_t{0};
  return first_true([&](std::uint64_t m) {
    const std::uint64_t events = k + m;
    if (events == 0) return false;
    return regularized_beta(bound, static_cast<double>(events), static_cast<double>(n - k) + 1.0) <
           1.0 - confidence;
  });
}

}  // namespace tetra::sim
