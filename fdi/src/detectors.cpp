#include "tetra/fdi/detectors.hpp"

#include "tetra/fdi/config.hpp"

#include <cmath>
#include <limits>

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

namespace tetra::fdi {

namespace {

constexpr double kVectorOvershoot = 0.8;  // b − h for Crosier's statistic (detectors.hpp)
constexpr int kArlSteps = 400;            // trapezoid steps of the ARL integral (relative error < 1e-3)
constexpr int kBiasNodes = 32;            // nodes of the average over the parity bias, out to its reach

double int_pow(double x, int n) {
  double r = 1.0;
  for (int i = 0; i < n; ++i) r *= x;
  return r;
}

//! Two-sided scalar CUSUM with the parity mean μ: both branches, 1/ARL = 1/ARL⁺ + 1/ARL⁻.
double scalar_alarm_rate(double mu, double k, double h) {
  return 1.0 / cusum_arl(mu, k, h) + 1.0 / cusum_arl(-mu, k, h);
}

}  // namespace

double vector_cusum_arl(int dof, double k, double h) {
  if (dof <= 1) return cusum_arl(0.0, k, h);
  const double b = h + kVectorOvershoot;
  const double dy = b / kArlSteps;
  double inner = 0.0;  // ∫₀ʸ z^{d−1} e^{−2kz} dz
  double outer = 0.0;
  double f_prev = 0.0;  // z^{d−1} e^{−2kz} at z = 0 (d ≥ 2)
  double g_prev = 0.0;  // outer integrand at 0 (→ 0 like y/d)
  for (int j = 1; j <= kArlSteps; ++j) {
    const double y = j * dy;
    const double f = int_pow(y, dof - 1) * std::exp(-2.0 * k * y);
    inner += 0.5 * (f_prev + f) * dy;
    f_prev = f;
    const double g = 2.0 * std::exp(2.0 * k * y) * inner / int_pow(y, dof - 1);
    outer += 0.5 * (g_prev + g) * dy;
    g_prev = g;
  }
  return outer;
}

double cusum_arl0_with_bias(int dof, double k, double h, double bias_sigma) {
  if (!(bias_sigma > 0.0)) {
    return dof <= 1 ? 1.0 / scalar_alarm_rate(0.0, k, h) : vector_cusum_arl(dof, k, h);
  }
  if (dof >= 2) {
    // A mean μ speeds the escape through each direction û as a one-dimensional shift x = μ·û would speed one
    // branch of Siegmund's CUSUM with the same b; x ~ N(0, s²) for every û.
    const double h1 = h + kVectorOvershoot - kSiegmundOvershoot;  // Siegmund's formula with b = h + 0.8
    const double arl_free = cusum_arl(0.0, k, h1);
    double tilt = 0.0;
    double weight = 0.0;
    for (int j = -kBiasNodes; j <= kBiasNodes; ++j) {
      const double x = design::cusum_bias_average_reach * j / kBiasNodes;
      const double w = std::exp(-0.5 * x * x);
      tilt += w * arl_free / cusum_arl(bias_sigma * x, k, h1);
      weight += w;
    }
    return vector_cusum_arl(dof, k, h) * weight / tilt;
  }
  // d = 1: E[1/ARL] over |μ| = s·x, x ~ |N(0, 1)|, both branches of Siegmund's formula, on a grid out to x
  // = 6.
  const double dx = design::cusum_bias_average_reach / kBiasNodes;
  double rate = 0.0;
  double weight = 0.0;
  for (int j = 0; j <= kBiasNodes; ++j) {
    const double x = (j + 0.5) * dx;
    const double w = std::exp(-0.5 * x * x);
    rate += w * scalar_alarm_rate(bias_sigma * x, k, h);
    weight += w;
  }
  return weight / rate;
}

CusumDesign cusum_design(int dof, double k, double arl0, double bias_sigma, double tolerance_sigmas) {
  const CusumDesign averaged{k, cusum_threshold(dof, k, arl0, bias_sigma), true};
  if (!(bias_sigma > 0.0)) return averaged;
  // At the tolerance's edge the statistic drifts as a drift-free CUSUM of reference k: h is that one's.
  const CusumDesign absorbed{k + tolerance_sigmas * bias_sigma, cusum_threshold(dof, k, arl0, 0.0), false};
  if (!std::isfinite(averaged.h)) return absorbed;
  // The delay to the design shift 2k, (h + overshoot) / (2k − reference): none once the reference reaches it.
  const auto delay = [k](const CusumDesign& d) {
    return d.k < 2.0 * k ? (d.h + kSiegmundOvershoot) / (2.0 * k - d.k)
                         : std::numeric_limits<double>::infinity();
  };
  return delay(averaged) <= design::cusum_average_kept_within * delay(absorbed) ? averaged : absorbed;
}

double cusum_threshold(int dof, double k, double arl0, double bias_sigma) {
  // ln ARL₀ grows about linearly in h: regula falsi (Illinois) on it within a bracket found by doubling.
  const auto f = [&](double h) { return std::log(cusum_arl0_with_bias(dof, k, h, bias_sigma) / arl0); };
  double lo = 0.0;
  double f_lo = f(lo);
  if (f_lo >= 0.0) return 0.0;
  double hi = 8.0;
  double f_hi = f(hi);
  while (f_hi < 0.0 && hi < 1e4) {
    lo = hi;
    f_lo = f_hi;
    hi *= 2.0;
    f_hi = f(hi);
  }
  // No h up to the bracket's end holds the ARL (a mean beyond k drifts the statistic up whatever h), or the
  // ARL overflowed: no threshold.
  if (!(f_hi >= 0.0)) return std::numeric_limits<double>::infinity();
  int side = 0;
  for (int it = 0; it < 60 && hi - lo > 1e-6; ++it) {
    const double h = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
    const double fh = f(h);
    if (std::abs(fh) < 1e-9) return h;
    if (fh < 0.0) {
      lo = h;
      f_lo = fh;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = h;
      f_hi = fh;
      if (side == 1) f_lo *= 0.5;
      side = 1;
    }
  }
  return hi;
}

}  // namespace tetra::fdi
