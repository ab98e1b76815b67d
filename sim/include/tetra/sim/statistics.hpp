#pragma once
// Confidence intervals for a campaign's rates (docs/campaign.md, "Statistics"): the exact
// (Clopper–Pearson) binomial interval of a proportion, the exact (Garwood) Poisson interval of a count,
// and the special functions they rest on (the regularized incomplete beta function and the beta and gamma
// quantiles). Every function is total: arguments outside their domain give NaN, never an abort.
//
//   Clopper–Pearson, k successes in n trials, confidence c (α = 1 − c), two-sided:
//     lower = B⁻¹(α/2; k, n − k + 1) (0 for k = 0),  upper = B⁻¹(1 − α/2; k + 1, n − k) (1 for k = n);
//     one-sided upper bound at c: B⁻¹(c; k + 1, n − k).
//   Garwood, k events, confidence c, two-sided on the mean count:
//     lower = Γ⁻¹(α/2; k) (0 for k = 0),  upper = Γ⁻¹(1 − α/2; k + 1);  one-sided upper: Γ⁻¹(c; k + 1).
// (B⁻¹(p; a, b) the p-quantile of the Beta(a, b) law, Γ⁻¹(p; a) that of the Gamma(a, 1) law.)

#include <cstdint>
#include <optional>

namespace tetra::sim {

//! I_x(a, b), the regularized incomplete beta function (the Beta(a, b) law's CDF at x), a, b > 0.
double regularized_beta(double x, double a, double b);
//! x in [0, 1] with I_x(a, b) = p (bisection to adjacent doubles: full relative precision).
double beta_quantile(double p, double a, double b);
//! x ≥ 0 with P(a, x) = p, P the regularized lower incomplete gamma function (the Gamma(a, 1) law's CDF):
//! half the χ² quantile with 2a degrees of freedom (tetra/core/allan_stats.hpp).
double gamma_quantile(double p, double a);

struct Interval {
  double lower = 0.0;
  double upper = 0.0;
};

//! Two-sided Clopper–Pearson interval of a proportion, k of n (k ≤ n, n ≥ 1), at `confidence` in (0, 1).
Interval clopper_pearson(std::uint64_t k, std::uint64_t n, double confidence);
//! One-sided Clopper–Pearson bounds at `confidence`: the proportion is below `upper` (above `lower`)
//! with that confidence.
double clopper_pearson_upper(std::uint64_t k, std::uint64_t n, double confidence);
double clopper_pearson_lower(std::uint64_t k, std::uint64_t n, double confidence);

//! Two-sided Garwood interval of a Poisson mean from k observed events, at `confidence`.
Interval garwood(std::uint64_t k, double confidence);
//! One-sided Garwood bounds on the mean count at `confidence`.
double garwood_upper(std::uint64_t k, double confidence);
double garwood_lower(std::uint64_t k, double confidence);

//! [runs] the fewest further trials m such that, with no further event, clopper_pearson_upper(k, n + m,
//! confidence) < bound; nullopt when more than kMaxFurtherTrials would be needed (or bound ≤ 0).
std::optional<std::uint64_t> further_trials_below(std::uint64_t k, std::uint64_t n, double bound,
                                                  double confidence);
//! [runs] the fewest further trials m such that, with an event in every one,
//! clopper_pearson_lower(k + m, n + m, confidence) > bound; nullopt above kMaxFurtherTrials (or bound ≥ 1).
std::optional<std::uint64_t> further_trials_above(std::uint64_t k, std::uint64_t n, double bound,
                                                  double confidence);
//! The largest count of further trials the two functions above search.
inline constexpr std::uint64_t kMaxFurtherTrials = 1'000'000'000'000ULL;

}  // namespace tetra::sim
