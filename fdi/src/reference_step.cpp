#include "reference_step.hpp"

#include <algorithm>
#include <cmath>

#include "tetra/core/allan_stats.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi::detail {

ReferenceStep::ReferenceStep(const PipelineConfig& config)
    : threshold_(allan::chi2_quantile(
          1.0 - allocated_probability(config, BudgetTest::kReferenceCheck) / kCapacity, 3.0)) {}

void ReferenceStep::add(const Eigen::Vector3d& z_rad, const Eigen::Vector3d& s_rad2, double reference_var_rad2,
                        double turn_rad) {
  Sample& s = ring_[static_cast<std::size_t>(head_)];
  s.z = z_rad;
  s.w = s_rad2.cwiseInverse();
  s.rho = (reference_var_rad2 * s.w).cwiseMin(1.0);
  s.turn_rad = turn_rad;
  head_ = (head_ + 1) % kCapacity;
  count_ = std::min(count_ + 1, kCapacity);
}

StepFit ReferenceStep::evaluate(double calibration_fraction) const {
  StepFit best;
  const int m = count_;
  if (m < 3) return best;  // a step and two residual degrees of freedom per axis at least
  // Σwz² per axis over the window, and the rotation from its first sample to its last.
  Eigen::Vector3d q0 = Eigen::Vector3d::Zero();
  double turn = 0.0;
  for (int k = 0; k < m; ++k) {
    const Sample& s = at(k);
    q0 += s.w.cwiseProduct(s.z).cwiseProduct(s.z);
    if (k > 0) turn += s.turn_rad;
  }
  const double allowed = calibration_fraction * turn;  // [rad] a calibration's step within its tolerance
  // Onsets from the newest back: A = Σ w g z, C = Σ w g² from the onset on (g_j = 1, g_{k+1} = ρ_k·g_k),
  // and Π ρ the share of the step the filter has not yet taken.
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), c = Eigen::Vector3d::Zero();
  Eigen::Vector3d left = Eigen::Vector3d::Ones();
  for (int j = m - 1; j >= 0; --j) {
    const Sample& s = at(j);
    a = s.w.cwiseProduct(s.z) + s.rho.cwiseProduct(a);
    c = s.w + s.rho.cwiseProduct(s.rho).cwiseProduct(c);
    if (j < m - 1) left = left.cwiseProduct(s.rho);
    double statistic = 0.0;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (int ax = 0; ax < 3; ++ax) {
      step[ax] = a[ax] / c[ax];
      const double beyond = std::max(0.0, std::abs(step[ax]) - allowed);
      const double ratio = std::max(1.0, (q0[ax] - a[ax] * a[ax] / c[ax]) / (m - 1));
      statistic += beyond * beyond * c[ax] / ratio;
    }
    if (statistic > best.statistic) {
      best.statistic = statistic;
      best.step_rad = step;
      best.absorbed = Eigen::Vector3d::Ones() - left;
    }
  }
  return best;
}

}  // namespace tetra::fdi::detail
