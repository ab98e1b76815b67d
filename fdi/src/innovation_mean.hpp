#pragma once
// What the reference shows of the attitude's error now (docs/fdi.md, "The protection level"): under the
// hypotheses in which the reference is good (H0 and a common drift of the gyros, Hdrift), a used sample's
// innovation z = e + v measures the attitude error e itself, v the reference's noise. A common drift below
// the detectors (a warming unit) grows e before the drift match has the mean it needs, and the filter's
// sigma, built on the stated bias model, does not follow it; the innovations do. Their exponentially weighted
// mean over τ (reference_window_s), per axis with weights 1/S_aa,
//
//   m_a = Σ λ_k z_a,k/S_aa,k / Σ λ_k/S_aa,k,   var(m_a) = Σ λ_k²/S_aa,k / (Σ λ_k/S_aa,k)²,
//
// λ_k = exp(−age_k/τ), is what the protection level carries for Hdrift: PL ≥ |m| + K·√(σ_a² + var(m_a)); and
// sigma what of it the filter's σ does not cover (excess_rad). A ramp of e lags in m by its rate times τ; the
// filter's σ and the mean's own noise cover the rest.

#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

class InnovationMean {
 public:
  explicit InnovationMean(double tau_s) : tau_s_(tau_s) {}
  //! No samples: the term is absent until the next one.
  void reset() {
    weight_.setZero();
    weighted_.setZero();
    weight_squared_.setZero();
    last_ns_ = -1;
  }
  //! A used sample at `now_ns`: its innovation `z_rad` and the innovation covariance's diagonal `s_rad2`.
  void add(std::int64_t now_ns, const Eigen::Vector3d& z_rad, const Eigen::Vector3d& s_rad2) {
    if (last_ns_ >= 0) {
      const double decay = std::exp(-ns_to_seconds(now_ns - last_ns_) / tau_s_);
      weight_ *= decay;
      weighted_ *= decay;
      weight_squared_ *= decay * decay;
    }
    last_ns_ = now_ns;
    const Eigen::Vector3d w = s_rad2.cwiseInverse();
    weight_ += w;
    weighted_ += w.cwiseProduct(z_rad);
    weight_squared_ += w;
    mean_rad_ = weighted_.cwiseQuotient(weight_);  // once a sample, read at every epoch
    variance_rad2_ = weight_squared_.cwiseQuotient(weight_.cwiseAbs2());
  }
  bool empty() const { return last_ns_ < 0; }
  //! [rad] per axis the weighted mean m
  const Eigen::Vector3d& mean_rad() const { return mean_rad_; }
  //! [rad²] per axis its variance
  const Eigen::Vector3d& variance_rad2() const { return variance_rad2_; }
  //! [rad] the error the mean shows beyond what the filter's `sigma_rad` and the mean's own noise cover:
  //! √max(0, |m|² − Σ var(m_a) − Σ σ_a²), |m|² being e_m² + Σ var(m_a) on average, e_m the error's weighted
  //! mean, whose square σ covers when it tells the truth (0 without samples).
  double excess_rad(const Eigen::Vector3d& sigma_rad) const {
    if (empty()) return 0.0;
    const double excess = mean_rad_.squaredNorm() - variance_rad2_.sum() - sigma_rad.squaredNorm();
    return excess > 0.0 ? std::sqrt(excess) : 0.0;
  }

 private:
  double tau_s_;
  Eigen::Vector3d weight_ = Eigen::Vector3d::Zero();          //!< Σ λ/S
  Eigen::Vector3d weighted_ = Eigen::Vector3d::Zero();        //!< Σ λ·z/S
  Eigen::Vector3d weight_squared_ = Eigen::Vector3d::Zero();  //!< Σ λ²/S
  Eigen::Vector3d mean_rad_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d variance_rad2_ = Eigen::Vector3d::Zero();
  std::int64_t last_ns_ = -1;
};

}  // namespace tetra::fdi::detail
