#pragma once
// While the reference is rejected, the data hold two explanations the single-fault argument cannot always
// tell apart: the reference is wrong, or the gyros are, by a fault their parity does not see (two faults that
// cancel in it, a common-mode error). The rejected samples' innovations against the gyro-propagated attitude
// are that attitude's error under the second explanation. A weighted line fitted per axis over them,
// evaluated now, plus three times the σ of that prediction, bounds it; the published sigma carries the bound
// in quadrature until the reference is used again (docs/fdi.md, "Reference consistency"). Under the first
// explanation the bound is only conservative. Every rejection starts it, a `jump` too: a fast enough drift of
// the gyro attitude (two cancelling 1e-3 deg/s biases: 20″ in 6 s) first shows as one.

#include <cstdint>

#include <Eigen/Core>

namespace tetra::fdi::detail {

class DisagreementTrend {
 public:
  //! The reference was rejected at `now_ns`: the fit starts empty.
  void start(std::int64_t now_ns);
  //! Not rejected any more (or reset): no bound.
  void stop() { active_ = false; }
  bool active() const { return active_; }
  //! One rejected sample's innovation `z` [rad] with its per-axis variance `s_rad2`.
  void add(std::int64_t now_ns, const Eigen::Vector3d& z, const Eigen::Vector3d& s_rad2);
  //! [rad] per axis: |fitted line at now| + 3σ of it; zero when inactive or before a sample.
  Eigen::Vector3d bound(std::int64_t now_ns) const;

 private:
  bool active_ = false;
  std::int64_t start_ns_ = 0;
  int count_ = 0;
  Eigen::Vector3d s0_ = Eigen::Vector3d::Zero();   //!< Σw (w = 1/S_aa)
  Eigen::Vector3d s1_ = Eigen::Vector3d::Zero();   //!< Σw·t
  Eigen::Vector3d s2_ = Eigen::Vector3d::Zero();   //!< Σw·t²
  Eigen::Vector3d sz_ = Eigen::Vector3d::Zero();   //!< Σw·z
  Eigen::Vector3d stz_ = Eigen::Vector3d::Zero();  //!< Σw·t·z
};

}  // namespace tetra::fdi::detail
