#pragma once
// Statistics behind the Allan-deviation confidence intervals (NIST SP 1065, W. J. Riley, "Handbook of
// Frequency Stability Analysis", 2008, §5.3): the χ² distribution, and the equivalent degrees of
// freedom (EDF) of the overlapping Allan variance for the power-law noise types.
//
// A confidence interval of an estimated variance s² with `edf` degrees of freedom is
//   s²·edf / χ²((1+p)/2; edf)  ≤  σ²  ≤  s²·edf / χ²((1−p)/2; edf)
// for a two-sided confidence level p.

#include <cstdint>

namespace tetra::allan {

//! Regularized lower incomplete gamma function P(a, x) = γ(a, x)/Γ(a), a > 0, x ≥ 0.
//! Series for x < a + 1, continued fraction otherwise; relative accuracy about 1e-14.
double regularized_gamma_p(double a, double x);

//! Q(a, x) = 1 − P(a, x), computed without cancellation in the upper tail.
double regularized_gamma_q(double a, double x);

//! CDF of the χ² distribution with `dof` > 0 (not necessarily integer) degrees of freedom.
double chi2_cdf(double x, double dof);
//! Survival function 1 − CDF of the χ² distribution.
double chi2_sf(double x, double dof);

//! Quantile of the χ² distribution: x such that chi2_cdf(x, dof) = p, for 0 < p < 1, dof > 0.
//! Wilson–Hilferty start, then Newton steps on chi2_cdf kept inside a shrinking bracket.
//! Returns NaN for p or dof out of range.
double chi2_quantile(double p, double dof);

//! Power-law noise types as seen by the Allan variance of rate (frequency) data. In IEEE 952 terms:
//! quantization ≈ white phase (angle) noise, angle random walk = white rate (FM) noise, bias
//! instability = flicker rate noise, rate random walk = random-walk rate noise.
enum class NoiseType {
  kWhitePhase,      //!< α = +2, ADEV slope −1 (quantization)
  kWhiteRate,       //!< α = 0,  ADEV slope −½ (angle random walk)
  kFlickerRate,     //!< α = −1, ADEV slope 0 (bias instability)
  kRandomWalkRate,  //!< α = −2, ADEV slope +½ (rate random walk; also used for rate ramp)
};

const char* noise_type_name(NoiseType type);

//! EDF of the fully overlapping Allan variance (simple approximations of Howe, Allan and Barnes as
//! tabulated in NIST SP 1065 §5.3.2). `phase_points` is the number of phase (angle) points N, one
//! more than the number of rate samples; `m` the averaging factor (τ = m·τ0), 1 ≤ m ≤ (N−1)/2.
//! The formulas are approximations; near m = N/2 some fall below 1, so the result is clamped to
//! at least 1.
double overlapping_avar_edf(NoiseType type, double phase_points, double m);

}  // namespace tetra::allan
