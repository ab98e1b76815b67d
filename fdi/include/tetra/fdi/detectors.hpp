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

}  // namespace tetra::fdi
