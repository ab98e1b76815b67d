#pragma once
// Covariance of the time means of correlated gyro noise over intervals, for the calibration's 1σ.
//
// A calibration averages each gyro over sequences of about a minute. White rate noise (N) averages down
// as 1/√n within a sequence and is independent between sequences; the slow terms do not:
//   bias instability B — a first-order Gauss–Markov rate with correlation time T_c and stationary
//     σ_GM = kGaussMarkovSigmaPerB·B (the model of the simulator, docs/sim.md), autocovariance
//     σ_GM²·exp(−|t−u|/T_c);
//   rate random walk K — a Wiener rate from the start of the log, covariance K²·min(t − t₀, u − t₀).
// For intervals I_j = [a_j, b_j] the means m_j = (1/|I_j|)∫_{I_j} x dt have
//   cov(m_j, m_k) = (1/(|I_j||I_k|)) ∫_{I_j}∫_{I_k} R(t, u) du dt,
// evaluated here in closed form (intervals either identical or disjoint).

#include <vector>

#include <Eigen/Core>

#include "tetra/core/calibration_file.hpp"

namespace tetra {

//! σ_GM / B: stationary σ of the Gauss–Markov process whose Allan-deviation peak equals IEEE 952's
//! bias-instability floor 0.664·B (the peak of that process is 0.6174·σ_GM at τ = 1.893·T_c).
inline constexpr double kGaussMarkovSigmaPerB = 1.0760;

//! A time interval [begin_s, end_s] over which a sequence mean is taken.
struct TimeInterval {
  double begin_s = 0.0;  //!< [s]
  double end_s = 0.0;    //!< [s]
};

//! M×M covariance [(deg/s)²] of the interval means of the correlated terms of `noise` (B as a
//! Gauss–Markov process with correlation time `correlation_s`, K as a rate random walk starting at
//! `start_s`). White noise (N) and quantization are not included: the caller measures those from the
//! scatter within each interval. Zero where the terms are absent. Intervals must not overlap unless equal.
Eigen::MatrixXd correlated_mean_covariance(const std::vector<TimeInterval>& intervals, const GyroNoise& noise,
                                           double correlation_s, double start_s);

}  // namespace tetra
