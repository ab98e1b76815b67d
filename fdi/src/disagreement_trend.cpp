#include "disagreement_trend.hpp"

#include <cmath>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

namespace {}  // namespace

void DisagreementTrend::start(std::int64_t now_ns) {
  active_ = true;
  start_ns_ = now_ns;
  count_ = 0;
  s0_.setZero();
  s1_.setZero();
  s2_.setZero();
  sz_.setZero();
  stz_.setZero();
}

void DisagreementTrend::add(std::int64_t now_ns, const Eigen::Vector3d& z, const Eigen::Vector3d& s_rad2) {
  if (!active_) return;
  const double t = ns_to_seconds(now_ns - start_ns_);
  const Eigen::Vector3d w = s_rad2.cwiseMax(1e-30).cwiseInverse();
  s0_ += w;
  s1_ += w * t;
  s2_ += w * t * t;
  sz_ += w.cwiseProduct(z);
  stz_ += w.cwiseProduct(z) * t;
  ++count_;
}

Eigen::Vector3d DisagreementTrend::bound(std::int64_t now_ns) const {
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  if (!active_ || count_ == 0) return b;
  const double t = ns_to_seconds(now_ns - start_ns_);
  for (int a = 0; a < 3; ++a) {
    const double det = s0_[a] * s2_[a] - s1_[a] * s1_[a];
    if (count_ < 3 || det <= 1e-12 * s0_[a] * s2_[a]) {
      // Too few samples for a slope: the mean innovation and its σ.
      b[a] = std::abs(sz_[a] / s0_[a]) + design::trend_margin_sigmas / std::sqrt(s0_[a]);
      continue;
    }
    const double slope = (s0_[a] * stz_[a] - s1_[a] * sz_[a]) / det;
    const double offset = (s2_[a] * sz_[a] - s1_[a] * stz_[a]) / det;
    const double var = (s2_[a] - 2.0 * t * s1_[a] + t * t * s0_[a]) / det;
    b[a] = std::abs(offset + slope * t) + design::trend_margin_sigmas * std::sqrt(std::max(var, 0.0));
  }
  return b;
}

}  // namespace tetra::fdi::detail
