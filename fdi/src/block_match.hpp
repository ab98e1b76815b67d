#pragma once
// The block matches' one CUSUM (parity_bias_match.hpp, reference_noise_match.hpp, reference_bias_match.hpp),
// and the reference's mean-innovation statistic. The CUSUM takes a block statistic u that is χ²_d while the
// model holds, against the alternative that the block's covariance is ρ times the predicted. The
// log-likelihood ratio's CUSUM,
//
//   g ← max(0, g + ½·((1 − 1/ρ)·u − d·ln ρ)),
//
// has by Wald's bound a mean run length of at least e^h blocks without such an error at the threshold h;
// each match sets h = ln(1/(p·n)) from its budget share p per sample and the block's n samples.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace tetra::fdi::detail {

//! The CUSUM `g` after a block whose statistic `u` has `dof` degrees of freedom under the model.
inline double block_cusum_step(double g, double u, double dof) {
  return std::max(0.0, g + 0.5 * ((1.0 - 1.0 / design::block_match_ratio) * u -
                                  dof * std::log(design::block_match_ratio)));
}

//! The mean-innovation test's χ²₃ from per-axis sums Σ1/S_aa (`sw`) and Σz_a/S_aa (`swz`): Σ_a swz_a²/sw_a
//! (the reference's bias test and the common-drift match, reference_consistency.hpp,
//! reference_bias_match.hpp).
inline double mean_innovation_chi2(const Eigen::Vector3d& sw, const Eigen::Vector3d& swz) {
  double chi2 = 0.0;
  for (int a = 0; a < 3; ++a) chi2 += swz[a] * swz[a] / sw[a];
  return chi2;
}

//! The threshold h = ln(1/(p·n)) for `per_block` = p·n (p per sample, n the block's samples), at least ln 2.
inline double block_cusum_threshold(double per_block) {
  return -std::log(std::min(per_block, 0.5));
}

}  // namespace tetra::fdi::detail
