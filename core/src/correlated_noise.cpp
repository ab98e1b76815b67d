// Closed-form double integrals of the Gauss–Markov and random-walk autocovariances (correlated_noise.hpp).
#include "tetra/core/correlated_noise.hpp"

#include <algorithm>
#include <cmath>

namespace tetra {

namespace {

//! ∫_I∫_J exp(−|t−u|/T) du dt for I = J, or I entirely before J (the touching case included).
double gauss_markov_integral(const TimeInterval& i, const TimeInterval& j, double tc_s, bool same) {
  if (same) {
    const double x = (i.end_s - i.begin_s) / tc_s;
    return 2.0 * tc_s * tc_s * (x + std::expm1(-x));  // 2T²(x − 1 + e^{−x}), accurate for small x
  }
  const auto e = [tc_s](double gap_s) { return std::exp(-std::max(0.0, gap_s) / tc_s); };
  return tc_s * tc_s *
         (e(j.begin_s - i.end_s) - e(j.end_s - i.end_s) - e(j.begin_s - i.begin_s) + e(j.end_s - i.begin_s));
}

//! ∫_I∫_J min(t, u) du dt (times from the walk's start) for I = J, or I entirely before J.
double random_walk_integral(const TimeInterval& i, const TimeInterval& j, bool same) {
  const double a = i.begin_s;
  const double b = i.end_s;
  if (same) return (b * b * b - a * a * a) / 3.0 - a * a * (b - a);
  return (j.end_s - j.begin_s) * (b * b - a * a) / 2.0;  // min(t, u) = t for t ∈ I before u ∈ J
}

}  // namespace

Eigen::MatrixXd correlated_mean_covariance(const std::vector<TimeInterval>& intervals, const GyroNoise& noise,
                                           double correlation_s, double start_s) {
  const auto m = static_cast<Eigen::Index>(intervals.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(m, m);
  const double b_dps = noise.bias_instability_dps.value_or(0.0);
  const double k_dps_rts = noise.rate_random_walk_dps_per_rts.value_or(0.0);
  const double gm_var = b_dps > 0.0 && correlation_s > 0.0 ? std::pow(kGaussMarkovSigmaPerB * b_dps, 2) : 0.0;
  const double rw_var = k_dps_rts * k_dps_rts;
  if (gm_var == 0.0 && rw_var == 0.0) return cov;
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index k = j; k < m; ++k) {
      TimeInterval first = intervals[static_cast<std::size_t>(j)];
      TimeInterval second = intervals[static_cast<std::size_t>(k)];
      if (second.begin_s < first.begin_s) std::swap(first, second);
      first.begin_s -= start_s;
      first.end_s -= start_s;
      second.begin_s -= start_s;
      second.end_s -= start_s;
      const bool same = j == k;
      const double integral = gm_var * gauss_markov_integral(first, second, correlation_s, same) +
                              rw_var * random_walk_integral(first, second, same);
      const double length_product = (first.end_s - first.begin_s) * (second.end_s - second.begin_s);
      cov(j, k) = length_product > 0.0 ? integral / length_product : 0.0;
      cov(k, j) = cov(j, k);
    }
  }
  return cov;
}

}  // namespace tetra
