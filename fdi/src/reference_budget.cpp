#include "reference_budget.hpp"

#include <algorithm>
#include <cmath>

#include "quadrature.hpp"
#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

ReferenceBudget::ReferenceBudget(const PipelineConfig& config)
    : bias_rad_(config.reference_bias_arcsec * kArcsecToRad),
      latency_max_s_(config.reference_latency_max_s),
      hold_s_(config.reference_window_s) {}

void ReferenceBudget::reset() {
  used_ = false;
  last_s_ = 0.0;
  rate_held_rad_s_.setZero();
}

void ReferenceBudget::used(double time_s, const Eigen::Vector3d& omega_B_rad_s) {
  const double decay = used_ ? std::exp(-std::max(time_s - last_s_, 0.0) / hold_s_) : 0.0;
  rate_held_rad_s_ = (decay * rate_held_rad_s_).cwiseMax(omega_B_rad_s.cwiseAbs());
  last_s_ = time_s;
  used_ = true;
}

Eigen::Vector3d ReferenceBudget::sigma_rad() const {
  if (!active()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d lag = latency_max_s_ * rate_held_rad_s_;
  return root_sum_square(lag, Eigen::Vector3d::Constant(std::hypot(bias_rad_, learned_rad_)));
}

}  // namespace tetra::fdi::detail
