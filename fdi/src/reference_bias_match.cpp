#include "reference_bias_match.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "block_match.hpp"
#include "mekf.hpp"
#include "tetra/core/allan_stats.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi::detail {

ReferenceBiasMatch::ReferenceBiasMatch(const PipelineConfig& config)
    : threshold_(
          allan::chi2_quantile(1.0 - allocated_probability(config, BudgetTest::kReferenceBiasMatch), 3.0)),
      long_window_ns_(seconds_to_ns(design::reference_long_windows * design::reference_bias_window_s)) {}

void ReferenceBiasMatch::reset() {
  restart();
  matched_ = false;
  ratio_ = 1.0;
  last_match_ns_ = -1;
  seen_from_ns_ = -1;
}

void ReferenceBiasMatch::restart() {
  start_ns_ = -1;
  sw_.setZero();
  swz_.setZero();
}

std::optional<DriftFinding> ReferenceBiasMatch::observe(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                                        const Eigen::Matrix3d& S, GyroMask active,
                                                        Mekf& filter) {
  if (start_ns_ < 0 || now_ns - start_ns_ > long_window_ns_) {  // consecutive windows, as the bias test's
    restart();
    start_ns_ = now_ns;
  }
  const Eigen::Vector3d w = S.diagonal().cwiseInverse();
  sw_ += w;
  swz_ += w.cwiseProduct(z_rad);
  const double statistic = mean_innovation_chi2(sw_, swz_);
  if (!(statistic > threshold_)) return std::nullopt;
  const Eigen::Vector3d mean_rad = swz_.cwiseQuotient(sw_);
  const double span_s = ns_to_seconds(now_ns - start_ns_);
  if (!match_mean(now_ns, mean_rad, span_s, active, filter)) return std::nullopt;
  restart();
  return DriftFinding{statistic, threshold_, ratio_};
}

double ReferenceBiasMatch::needed_ratio(const Eigen::Vector3d& mean_rad, double span_s, GyroMask active,
                                        const Mekf& filter) {
  if (!(span_s > 0.0)) return std::numeric_limits<double>::infinity();
  const double rate_rad_s = 2.0 * mean_rad.norm() / span_s;
  const double walk = design::block_match_ratio * rate_rad_s * rate_rad_s / span_s;  // [rad²/s³], ρ·|b|²/T
  double smallest = std::numeric_limits<double>::infinity();
  for (int id = 1; id <= filter.gyro_count(); ++id)
    if (has_gyro(active, id)) smallest = std::min(smallest, wander(filter.noise_model(id)));
  const double ratio = walk / smallest;
  return smallest > 0.0 && std::isfinite(ratio) ? ratio : std::numeric_limits<double>::infinity();
}

bool ReferenceBiasMatch::match_mean(std::int64_t now_ns, const Eigen::Vector3d& mean_rad, double span_s,
                                    GyroMask active, Mekf& filter) {
  const double needed = needed_ratio(mean_rad, drift_span_s(span_s, now_ns), active, filter);
  if (!may_explain(needed, now_ns)) return false;
  if (!persists(now_ns)) seen_from_ns_ = now_ns - seconds_to_ns(span_s);
  matched_ = true;
  ratio_ = next_ratio(needed, now_ns);
  last_match_ns_ = now_ns;
  open(active, filter);
  return true;
}

double ReferenceBiasMatch::wander(const GyroNoiseModel& m) {
  const double tc = m.gm_correlation_s;
  return m.rrw_rad_s_rts * m.rrw_rad_s_rts + 2.0 * m.gm_sigma_rad_s * m.gm_sigma_rad_s / tc +
         m.arw_rad_rts * m.arw_rad_rts / (tc * tc);
}

void ReferenceBiasMatch::open(GyroMask active, Mekf& filter) const {
  for (int id = 1; id <= filter.gyro_count(); ++id) {
    if (has_gyro(active, id)) filter.open_bias_model(id, 0.0, ratio_ * wander(filter.noise_model(id)));
  }
}

}  // namespace tetra::fdi::detail
