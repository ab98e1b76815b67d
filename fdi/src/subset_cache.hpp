#pragma once
// Everything that depends on the gyro subset only — weighted pseudoinverse, whitened parity matrix, noise per
// axis, the thresholds of the parity tests — computed once per subset, and the two kernels every stage uses
// to apply them (docs/fdi.md, "Noise model and normalized parity").

#include <unordered_map>

#include <Eigen/Core>

#include "tetra/core/correlated_noise.hpp"  // kGaussMarkovSigmaPerB
#include "tetra/core/geometry.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

struct Subset {
  GyroMask mask = 0;
  bool observable = false;
  int dof = 0;                    //!< parity dimension |S| − 3
  Eigen::Matrix3Xd pinv;          //!< 3×N weighted pseudoinverse (zero columns outside S)
  Eigen::MatrixXd parity;         //!< d×N normalized parity in 1/(rad/s) per √s: p = √T·W·y ~ N(0, I)
  Eigen::Vector3d arw_sq_rad2_s;  //!< [rad²/s] N² per body axis of the rate estimate
  Eigen::Vector3d bias_sigma_rad_s;  //!< [rad/s] 1σ rate bias per body axis left by the calibration
  double chi2_threshold = 0.0;       //!< instantaneous χ² threshold
  double jump_threshold = 0.0;       //!< one-epoch jump χ² threshold
  double cusum_k = 0.0;              //!< [σ] CUSUM reference
  double cusum_h = 0.0;              //!< [σ] CUSUM threshold
  double bias_wander_sigma = 0.0;    //!< [σ] per parity axis: the slowly wandering bias (B, K) in the parity
  double nominal_threshold = 0.0;    //!< χ²_d(1 − 1e-3): the slow parity mean back to nominal
  double glt_accept = 0.0;           //!< χ²_{d−1} quantile accepting a single-gyro hypothesis
  double glt_reject = 0.0;           //!< χ²_{d−1} quantile rejecting one
};

class SubsetCache {
 public:
  //! `geometry` weighted by each gyro's white rate noise N_i [rad/√s]; `bias_sigma_rad_s`: 1σ of each
  //! calibrated bias; `config` outlives the cache. `bias_wander_rad_s`: 1σ of each gyro's slowly wandering
  //! bias (bias instability and rate random walk, `bias_wander_sigma`); empty = none.
  SubsetCache(GyroGeometry geometry, Eigen::VectorXd bias_sigma_rad_s, const PipelineConfig& config,
              Eigen::VectorXd bias_wander_rad_s = {});

  //! The sample period T is known: thresholds follow from it. Every subset is built now for N ≤ 8 (a missing
  //! sample then never allocates); for larger N the full set and its leave-one-out subsets.
  void prepare(double period_s);
  bool ready() const { return period_s_ > 0.0; }
  double period_s() const { return period_s_; }
  double sqrt_period() const { return sqrt_period_; }

  //! The subset's constants, built on first use (only once `ready()`).
  const Subset& get(GyroMask mask) {
    const auto it = subsets_.find(mask);
    return it != subsets_.end() ? it->second : insert(mask);
  }
  //! The subset's constants if built already, else null.
  const Subset* find(GyroMask mask) const;
  //! Without a sample period, the full-rank test alone (at least 3 gyros spanning 3-D).
  bool observable(GyroMask mask) { return ready() ? get(mask).observable : tetra::gyro_count(mask) >= 3; }
  const GyroGeometry& geometry() const { return geometry_; }
  int gyro_count() const { return geometry_.gyro_count(); }

 private:
  const Subset& insert(GyroMask mask);
  void build(Subset& s, GyroMask mask) const;
  //! [σ] per parity axis: the wandering biases seen in the subset's normalized parity.
  double parity_bias_sigma(const Subset& s, GyroMask mask) const;

  GyroGeometry geometry_;              //!< weighted by N_i
  Eigen::VectorXd bias_sigma_rad_s_;   //!< [rad/s] per gyro
  Eigen::VectorXd bias_wander_rad_s_;  //!< [rad/s] per gyro (zeros when none)
  const PipelineConfig* config_;       //!< owned by the pipeline, outlives the cache
  double period_s_ = 0.0;
  double sqrt_period_ = 0.0;
  std::unordered_map<GyroMask, Subset> subsets_;
};

//! [rad/s] 1σ of a gyro's slowly wandering bias over the detectors' horizon: the stationary σ of the
//! bias-instability process (kBiasWanderPerB·B) and the rate random walk over `horizon_s` (K·√horizon), in
//! quadrature. B [rad/s], K [rad/s/√s].
double bias_wander_sigma(double bias_instability_rad_s, double rate_random_walk_rad_s_rts, double horizon_s);
//! σ_b / B: the stationary σ of a first-order Gauss–Markov bias whose Allan deviation peaks at the IEEE 952
//! floor 0.664·B (the simulator's bias-instability model, docs/sim.md).
inline constexpr double kBiasWanderPerB = kGaussMarkovSigmaPerB;

//! p_r = scale·Σ_{i∈mask} W(r, i)·v_i for the subset's d rows; returns Σ p_r². The one parity kernel.
inline double apply_parity(const Subset& s, GyroMask mask, const double* v, double scale, double* p) {
  const int n = static_cast<int>(s.parity.cols());
  double sum_sq = 0.0;
  for (int r = 0; r < s.dof; ++r) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i) {
      if (has_gyro(mask, i + 1)) acc += s.parity(r, i) * v[i];
    }
    p[r] = acc * scale;
    sum_sq += p[r] * p[r];
  }
  return sum_sq;
}

//! ω = Σ_{i∈mask} H*(:, i)·v_i. The one rate kernel.
inline Eigen::Vector3d apply_pinv(const Eigen::Matrix3Xd& pinv, GyroMask mask, const double* v) {
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < pinv.cols(); ++i) {
    if (has_gyro(mask, static_cast<int>(i) + 1)) w += pinv.col(i) * v[i];
  }
  return w;
}

}  // namespace tetra::fdi::detail
