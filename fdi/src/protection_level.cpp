#include "protection_level.hpp"

#include <cmath>
#include <limits>

#include "tetra/core/allan_stats.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {

ProtectionLevel::ProtectionLevel(const PipelineConfig& config)
    : k_md_(std::sqrt(allan::chi2_quantile(1.0 - config.integrity_risk, 1.0))) {}

Eigen::Vector3d ProtectionLevel::bound(const Subset& s, const Eigen::Vector3d& sigma_rad, std::int64_t now_ns,
                                       double sqrt_period) const {
  if (s.dof < 1 || !s.observable) return Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  const double period = sqrt_period * sqrt_period;
  const double t = std::max(0.0, ns_to_seconds(now_ns - anchor_ns_));
  const double reach =
      s.cusum_k * t + calibration_reach_ + (s.cusum_h + kSiegmundOvershoot) * period;  // [σ·s]
  Eigen::Vector3d fault = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < s.pinv.cols(); ++i) {
    if (!has_gyro(s.mask, static_cast<int>(i) + 1)) continue;
    const double w = s.parity_col_norm[i] * sqrt_period;  // [σ per rad/s]
    if (!(w > 0.0)) return Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    fault = fault.cwiseMax(s.pinv.col(i).cwiseAbs() * (reach / w));
  }
  return k_md_ * sigma_rad + fault;
}

}  // namespace tetra::fdi::detail
