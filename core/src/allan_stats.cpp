#include "tetra/core/allan_stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tetra::allan {

namespace {

constexpr double kEps = 1e-15;
// Both expansions need O(√a) terms near x ≈ a; 1e6 degrees of freedom need a few thousand.
constexpr int kMaxIterations = 1000000;

// P(a, x) by its power series, for x < a + 1.
double gamma_p_series(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < kMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kEps) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) = 1 − P(a, x) by its continued fraction (modified Lentz), for x ≥ a + 1.
double gamma_q_continued_fraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// Standard normal quantile by bisection + Newton on erfc (used only for the Wilson–Hilferty start).
double normal_quantile(double p) {
  double lo = -40.0;
  double hi = 40.0;
  double z = 0.0;
  for (int i = 0; i < 200; ++i) {
    const double cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
    if (cdf < p) {
      lo = z;
    } else {
      hi = z;
    }
    const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * 3.14159265358979323846);
    double next = pdf > 0.0 ? z - (cdf - p) / pdf : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - z) < 1e-15 * std::max(1.0, std::abs(z))) return next;
    z = next;
  }
  return z;
}

}  // namespace

double regularized_gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return 0.0;
  if (std::isinf(x)) return 1.0;
  if (x < a + 1.0) return gamma_p_series(a, x);
  return 1.0 - gamma_q_continued_fraction(a, x);
}

double regularized_gamma_q(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return 1.0;
  if (std::isinf(x)) return 0.0;
  if (x < a + 1.0) return 1.0 - gamma_p_series(a, x);
  return gamma_q_continued_fraction(a, x);
}

double chi2_cdf(double x, double dof) {
  if (x <= 0.0) return 0.0;
  return regularized_gamma_p(0.5 * dof, 0.5 * x);
}

double chi2_sf(double x, double dof) {
  if (x <= 0.0) return 1.0;
  return regularized_gamma_q(0.5 * dof, 0.5 * x);
}

double chi2_quantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0) || !std::isfinite(dof)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Bracket [lo, hi] with cdf(lo) < p ≤ cdf(hi).
  double lo = 0.0;
  double hi = std::max(1.0, dof);
  while (chi2_cdf(hi, dof) < p) {
    lo = hi;
    hi *= 2.0;
  }
  // Wilson–Hilferty: (χ²/k)^(1/3) is nearly normal with mean 1 − 2/(9k) and variance 2/(9k).
  const double v = 2.0 / (9.0 * dof);
  double x = dof * std::pow(std::max(0.0, 1.0 - v + normal_quantile(p) * std::sqrt(v)), 3.0);
  if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);

  const double a = 0.5 * dof;
  const double log_norm = -a * std::log(2.0) - std::lgamma(a);
  // In the upper tail solve sf(x) = 1 − p (exact in floating point for p > ½), which keeps the
  // digits that 1 − cdf would lose.
  const bool upper = p > 0.5;
  const double q = 1.0 - p;
  for (int i = 0; i < 300; ++i) {
    const double f = upper ? q - chi2_sf(x, dof) : chi2_cdf(x, dof) - p;
    if (f == 0.0) return x;
    if (f < 0.0) {
      lo = x;
    } else {
      hi = x;
    }
    const double pdf = std::exp(log_norm + (a - 1.0) * std::log(x) - 0.5 * x);
    double next = (pdf > 0.0 && std::isfinite(pdf)) ? x - f / pdf : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-15 * x || hi - lo <= 1e-15 * hi) return next;
    x = next;
  }
  return x;
}

const char* noise_type_name(NoiseType type) {
  switch (type) {
    case NoiseType::kWhitePhase:
      return "white-angle";
    case NoiseType::kWhiteRate:
      return "white-rate";
    case NoiseType::kFlickerRate:
      return "flicker-rate";
    case NoiseType::kRandomWalkRate:
      return "random-walk-rate";
  }
  return "unknown";
}

double overlapping_avar_edf(NoiseType type, double phase_points, double m) {
  const double n = phase_points;
  double edf = 1.0;
  switch (type) {
    case NoiseType::kWhitePhase:
      edf = (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m));
      break;
    case NoiseType::kWhiteRate:
      edf = (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * (4.0 * m * m / (4.0 * m * m + 5.0));
      break;
    case NoiseType::kFlickerRate:
      // m = 1: 2(N-2)^2/(2.3N-4.9) (Howe, Allan and Barnes 1981; NIST SP 1065 prints it without the
      // square, which gives EDF < 1 for any N and intervals about 100 times too wide).
      edf =
          m == 1.0 ? 2.0 * (n - 2.0) * (n - 2.0) / (2.3 * n - 4.9) : 5.0 * n * n / (4.0 * m * (n + 3.0 * m));
      break;
    case NoiseType::kRandomWalkRate:
      edf = (n - 2.0) / m * ((n - 1.0) * (n - 1.0) - 3.0 * m * (n - 1.0) + 4.0 * m * m) /
            ((n - 3.0) * (n - 3.0));
      break;
  }
  if (!std::isfinite(edf)) return 1.0;
  return std::max(1.0, edf);
}

}  // namespace tetra::allan
