#include "reference_step.hpp"

#include <algorithm>
#include <cmath>

#include "tetra/core/allan_stats.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi::detail {

ReferenceStep::ReferenceStep(const PipelineConfig& config)
    : threshold_(allan::chi2_quantile(
          1.0 - allocated_probability(config, BudgetTest::kReferenceCheck) / kCapacity, 3.0)) {}

void ReferenceStep::add(const Eigen::Vector3d& z_rad, const Eigen::Vector3d& s_rad2,
                        double reference_var_rad2, const Eigen::Vector3d& calibration_rad, double since_s) {
  Sample& s = ring_[static_cast<std::size_t>(head_)];
  for (int a = 0; a < 3; ++a) {
    const double w = 1.0 / s_rad2[a];
    s.w[a] = w;
    s.wz[a] = w * z_rad[a];
    s.wzz[a] = s.wz[a] * z_rad[a];
    s.rho[a] = std::min(reference_var_rad2 * w, 1.0);
    s.rho2[a] = s.rho[a] * s.rho[a];
  }
  s.calibration_rad = calibration_rad;
  s.since_s = since_s;
  head_ = (head_ + 1) % kCapacity;
  count_ = std::min(count_ + 1, kCapacity);
}

StepFit ReferenceStep::evaluate(double level) const {
  StepFit best;
  const int m = count_;
  if (m < 3) return best;  // a step and two residual degrees of freedom per axis at least
  // Σwz² per axis over the window, and what the calibration allows from its first sample to its last.
  Eigen::Vector3d q0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d allowed = Eigen::Vector3d::Zero();  // [rad] β
  for (int k = 0; k < m; ++k) {
    const Sample& s = at(k);
    for (int a = 0; a < 3; ++a) q0[a] += s.wzz[a];
    if (k > 0) allowed += s.calibration_rad;
  }
  // Onsets from the newest back: A = Σ w g z, C = Σ w g² from the onset on (g_j = 1, g_{k+1} = ρ_k·g_k),
  // and Π ρ the share of the step the filter has not yet taken. The residual ratio only lowers a term, so an
  // onset whose terms without it stay below `level` (and the best so far) is passed over.
  Eigen::Vector3d a_sum = Eigen::Vector3d::Zero(), c_sum = Eigen::Vector3d::Zero(), step, term;
  Eigen::Vector3d left = Eigen::Vector3d::Ones();
  for (int j = m - 1; j >= 0; --j) {
    const Sample& s = at(j);
    Eigen::Vector3d reach;  // max(0, |A| − β·C)²: the term times C, without a division
    for (int a = 0; a < 3; ++a) {
      a_sum[a] = s.wz[a] + s.rho[a] * a_sum[a];
      c_sum[a] = s.w[a] + s.rho2[a] * c_sum[a];
      if (j < m - 1) left[a] *= s.rho[a];
      const double r = std::max(0.0, std::abs(a_sum[a]) - allowed[a] * c_sum[a]);
      reach[a] = r * r;
    }
    // Σ reach_a/C_a ≤ the level, multiplied through by C₀C₁C₂ (with a margin far above the rounding).
    const double c01 = c_sum[0] * c_sum[1];
    const double bound = reach[0] * c_sum[1] * c_sum[2] + reach[1] * c_sum[0] * c_sum[2] + reach[2] * c01;
    if (bound <= (1.0 - 1e-9) * std::max(level, best.statistic) * c01 * c_sum[2]) continue;
    double statistic = 0.0;
    for (int a = 0; a < 3; ++a) {
      step[a] = a_sum[a] / c_sum[a];
      const double beyond = std::max(0.0, std::abs(step[a]) - allowed[a]);
      term[a] = beyond * beyond * c_sum[a];
    }
    for (int a = 0; a < 3; ++a) {
      const double ratio = std::max(1.0, (q0[a] - a_sum[a] * a_sum[a] / c_sum[a]) / (m - 1));
      statistic += term[a] / ratio;
    }
    if (statistic > best.statistic) {
      best.statistic = statistic;
      for (int a = 0; a < 3; ++a) {
        best.step_rad[a] = step[a];
        best.absorbed[a] = 1.0 - left[a];
      }
    }
  }
  return best;
}

RampFit ReferenceStep::ramp_fit() const {
  RampFit fit;
  const int m = count_;
  // Per axis from the newest sample back, for the onset j: the step's A = Σwgz, C = Σwg²; the ramp's
  // A_r = Σwhz, C_r = Σwh² and Y = Σwgh (the header's recursions: A_r(j) = A_r(j+1) + Δt_j·A(j),
  // C_r(j) = C_r(j+1) + 2Δt_j·ρ_j·Y(j+1) + Δt_j²·C(j), Y(j) = ρ_j·Y(j+1) + Δt_j·C(j)).
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), c = Eigen::Vector3d::Zero(), ar = Eigen::Vector3d::Zero();
  Eigen::Vector3d cr = Eigen::Vector3d::Zero(), y = Eigen::Vector3d::Zero();
  double span_s = 0.0;
  for (int j = m - 1; j >= 1; --j) {  // the oldest sample has no interval before it in the window
    const Sample& s = at(j);
    const double dt = s.since_s;
    span_s += dt;
    double step = 0.0;
    double ramp = 0.0;
    for (int x = 0; x < 3; ++x) {
      const double y_next = y[x];
      a[x] = s.wz[x] + s.rho[x] * a[x];
      c[x] = s.w[x] + s.rho2[x] * c[x];
      cr[x] += 2.0 * dt * s.rho[x] * y_next + dt * dt * c[x];
      ar[x] += dt * a[x];
      y[x] = s.rho[x] * y_next + dt * c[x];
      step += a[x] * a[x] / c[x];
      ramp += cr[x] > 0.0 ? ar[x] * ar[x] / cr[x] : 0.0;
    }
    fit.step_chi2 = std::max(fit.step_chi2, step);
    if (ramp > fit.ramp_chi2) {
      fit.ramp_chi2 = ramp;
      for (int x = 0; x < 3; ++x) fit.rate_rad_s[x] = cr[x] > 0.0 ? ar[x] / cr[x] : 0.0;
      fit.span_s = span_s;
    }
  }
  return fit;
}

}  // namespace tetra::fdi::detail
