#pragma once
// Statistics behind the fault detectors, written out so the documentation (docs/fdi.md), the
// pipeline and the tests use the same formulas.
//
//   χ² test: the normalized parity p ~ N(0, I_d) without fault; alarm when |p|² > χ²_d(1 − P_fa).
//   CUSUM (d = 1, two-sided), reference k = δ/2 for a shift of δ σ:
//     S⁺ ← max(0, S⁺ + p − k),  S⁻ ← max(0, S⁻ − p − k),  alarm when max(S⁺, S⁻) > h.
//   Siegmund's approximation of the average run length of one branch for a mean μ per step
//   (in σ units, drift μ − k) with b = h + 1.166:
//     ARL(Δ) = (exp(−2Δb) + 2Δb − 1) / (2Δ²),  Δ = μ − k   (Δ = 0: b²).
//   In control (μ = 0): ARL₀ one branch = ARL(−k); two-sided: 1/ARL₀ = 1/ARL⁺ + 1/ARL⁻ = 2/ARL(−k).
//   Delay for a shift δ ≥ k: ARL(δ − k) (≈ (h + 1.166)/(δ − k), Wald's approximation, when large).
//
//   Crosier's vector CUSUM (d ≥ 2), S ← (S + p)(1 − k/|S + p|) (0 when |S + p| ≤ k), alarm when |S| > h:
//   away from 0, |S| moves like a d-dimensional Bessel process with drift −k: a diffusion with unit variance
//   and drift −k + (d − 1)/(2r), reflected at 0. Its mean time to reach b from 0 is
//     ARL_d(k, b) = 2 ∫₀ᵇ e^{2ky} y^{1−d} ∫₀ʸ z^{d−1} e^{−2kz} dz dy,   b = h + 0.8
//   (d = 1 gives Siegmund's ARL(−k) above; the overshoot correction 0.8 replaces 1.166 for the vector
//   statistic, fitted to simulation for d = 2…4, k = 0.3…0.6, within ±0.1, i.e. ARL within ±10 %).
//
//   Reference noise with a slowly wandering bias (bias instability B, rate random walk K): the parity then
//   carries a quasi-static mean μ ~ N(0, s² I_d) (s in σ units, see cusum_arl0_with_bias). Alarms come
//   at the rate 1/ARL(μ) at each μ; the design holds for the average 1/ARL₀ = E_μ[1/ARL(μ)]:
//     d = 1: both branches of Siegmund's formula, k ∓ μ, averaged over μ numerically;
//     d ≥ 2: μ speeds the escape through each direction û as the shift x = μ·û speeds one branch of the
//            scalar CUSUM with the same b, and x ~ N(0, s²) for every û, so
//            1/ARL₀ = E_x[ARL(−k)/ARL(x − k)] / ARL_d(k, b)   (Siegmund's ARL with b = h + 0.8).
//   The threshold h is set so that this average meets the design.

namespace tetra::fdi {

//! P(χ²_d > x): survival function of the χ² distribution with d ≥ 1 degrees of freedom.
double chi2_survival(double x, int dof);
//! x such that P(χ²_d > x) = p, for 0 < p < 1.
double chi2_threshold(double p, int dof);

//! Siegmund's ARL of one CUSUM branch with reference k and threshold h, for a per-step mean
//! shift μ (all in σ units of the monitored statistic).
double cusum_arl(double mu, double k, double h);
//! Threshold h of a two-sided CUSUM with reference k whose in-control ARL is `arl0` (steps).
double cusum_threshold(double k, double arl0);

//! ARL of Crosier's vector CUSUM of dimension `dof` ≥ 1 with reference k and threshold h when the
//! statistic's norm drifts by −k per step away from 0 (the radial diffusion above; k may be negative: a
//! shift larger than k).
double vector_cusum_arl(int dof, double k, double h);
//! Siegmund's overshoot of a one-sided CUSUM's threshold (b − h), in its σ (docs/fdi.md, "Detection").
inline constexpr double kSiegmundOvershoot = 1.166;
//! In-control ARL of the CUSUM used for dimension `dof` (two-sided scalar for 1, Crosier's for ≥ 2) when
//! the parity carries a quasi-static mean N(0, bias_sigma² I) [σ units], averaged as 1/ARL₀ = E[1/ARL] over
//! a mean out to design::cusum_bias_average_reach × bias_sigma. A mean beyond k drifts the statistic up at
//! (mean − k) per step whatever h: once the reach passes k the average's h grows without bound (cusum_design
//! below).
double cusum_arl0_with_bias(int dof, double k, double h, double bias_sigma);

//! A CUSUM's reference and threshold for a quasi-static mean of 1σ `bias_sigma` per axis, in-control ARL
//! `arl0`, designed for a shift 2k. Two designs hold the ARL, each in its model: the mean averaged
//! (reference k, h from cusum_arl0_with_bias), or the mean a tolerance as the calibration's bound is
//! (reference k + tolerance_sigmas·bias_sigma, h the drift-free one of reference k: at the tolerance's edge
//! the statistic drifts as that CUSUM's, and holds ARL₀). The one that detects the 2k shift sooner
//! (h / (2k − reference)) is taken; the average where its h is finite and no later.
struct CusumDesign {
  double k = 0.0;  //!< [σ] reference
  double h = 0.0;  //!< [σ] threshold
  bool averaged =
      true;  //!< the mean averaged (true) or absorbed in the reference (false: k − the input k joins D)
};
CusumDesign cusum_design(int dof, double k, double arl0, double bias_sigma, double tolerance_sigmas);
//! Threshold h whose `cusum_arl0_with_bias` is `arl0` (steps).
double cusum_threshold(int dof, double k, double arl0, double bias_sigma);

}  // namespace tetra::fdi
