#include "tetra/fdi/detectors.hpp"

#include <cmath>

namespace tetra::fdi {

double chi2_survival(double x, int dof) {
  if (x <= 0.0) return 1.0;
  // Closed forms: even d: e^{−x/2} Σ_{j<d/2} (x/2)^j / j!;
  // odd d: erfc(√(x/2)) + e^{−x/2} Σ_{j=1}^{(d−1)/2} (x/2)^{j−1/2} / Γ(j + 1/2).
  const double half = 0.5 * x;
  if (dof % 2 == 0) {
    double term = std::exp(-half);
    double sum = term;
    for (int j = 1; j < dof / 2; ++j) {
      term *= half / j;
      sum += term;
    }
    return sum;
  }
  double sum = std::erfc(std::sqrt(half));
  double term = std::exp(-half) * std::sqrt(half) / std::tgamma(1.5);  // j = 1
  for (int j = 1; j <= (dof - 1) / 2; ++j) {
    sum += term;
    term *= half / (j + 0.5);
  }
  return sum;
}

double chi2_threshold(double p, int dof) {
  // Bisection on the monotone survival function; 200 halvings reach double precision.
  double lo = 0.0;
  double hi = 1.0;
  while (chi2_survival(hi, dof) > p) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (chi2_survival(mid, dof) > p) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

double cusum_arl(double mu, double k, double h) {
  const double b = h + 1.166;
  const double delta = mu - k;
  if (std::abs(delta) < 1e-9) return b * b;
  return (std::exp(-2.0 * delta * b) + 2.0 * delta * b - 1.0) / (2.0 * delta * delta);
}

double cusum_threshold(double k, double arl0) {
  // Two-sided in-control ARL = ARL(−k)/2, increasing in h.
  double lo = 0.0;
  double hi = 1.0;
  while (cusum_arl(0.0, k, hi) / 2.0 < arl0 && hi < 1e6) hi *= 2.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (cusum_arl(0.0, k, mid) / 2.0 < arl0) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return hi;
}

}  // namespace tetra::fdi
