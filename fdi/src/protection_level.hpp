#pragma once
// The integrity bound beside sigma (docs/fdi.md, "Protection level"): per body axis, the attitude error that
// a single-gyro fault just below the detection threshold can have caused since the last point it could have
// started, plus the filter's σ scaled to the integrity risk — as GNSS integrity monitoring (RAIM, ARAIM)
// publishes a protection level beside its accuracy.
//
// A fault f on gyro i moves the normalized parity by δ = f·|w_i| (w_i its parity column, in σ per rad/s).
// The CUSUM (reference k, threshold h) has not alarmed n epochs after an onset only if δ ≤ k + (h + 1.166)/n
// (its mean path, Siegmund's overshoot). Such a fault turned the attitude about axis a by at most
// |H*(a, i)|·f·n·T, so over the time t = n·T since the anchor (the run's start, or the last reference sample
// used) the bound is
//   PL_a = K·σ_a + max_i |H*(a, i)|/|w_i| · (k·t + ∫D dt + (h + 1.166)·T),   K = Φ⁻¹(1 − integrity_risk/2),
// D the calibration's bound the CUSUM adds to k at each epoch (0 without stated σ), integrated since the
// anchor. Without parity among the gyros used nothing detects a fault: the bound is +∞ (no integrity).

#include <cstdint>

#include <Eigen/Core>

#include "subset_cache.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

class ProtectionLevel {
 public:
  explicit ProtectionLevel(const PipelineConfig& config);

  //! The error is known (to σ) at `now_ns`: the start, or a reference sample used.
  void anchor(std::int64_t now_ns) {
    anchor_ns_ = now_ns;
    calibration_reach_ = 0.0;
  }
  //! The CUSUM's reference was k + `calibration_bound` [σ] for `dt_s` [s]: a fault that much larger goes
  //! unseen.
  void widen(double calibration_bound, double dt_s) { calibration_reach_ += calibration_bound * dt_s; }
  //! [rad] per axis, over the active subset `s` (its parity, k and h), with the published σ [rad].
  Eigen::Vector3d bound(const Subset& s, const Eigen::Vector3d& sigma_rad, std::int64_t now_ns,
                        double sqrt_period) const;
  double k_md() const { return k_md_; }

 private:
  double k_md_ = 0.0;
  std::int64_t anchor_ns_ = 0;
  double calibration_reach_ = 0.0;  //!< [σ·s] ∫ D dt since the anchor
};

}  // namespace tetra::fdi::detail
