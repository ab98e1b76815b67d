#pragma once
// What the reference has pulled the attitude by, beyond the gyros (docs/fdi.md, "A common drift below the
// detectors"): the filter's attitude against the gyros' own propagation from an anchor with the bias estimate
// b̂₀ it had then. The two differ by every reference update's correction δθ and by the bias estimate's change
// integrated, D = Σ R(q̂)·δθ − Σ R(q̂)·(b̂ − b̂₀)·Δt in the reference frame (b̂ is constant between the
// updates that move it). Kept as sums, Σ R·δθ, Σ R·b̂·Δt and Σ R·Δt, so that D holds against any anchor's b̂₀:
// over the bias block the drift matches judge and the one before it (a drift that began before the block,
// anchored at that block's start), and since the last drift match. When a mean innovation is matched as a
// drift of the gyros, the reference's bias is the other hypothesis the data leave standing: under it the
// attitude is off by the pull, which the protection level then covers (reference_budget.hpp).

#include <cstdint>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

class ReferencePull {
 public:
  //! Everything from `now_ns` on, the bias estimate then `bias_B_rad_s` [rad/s] (body).
  void start(std::int64_t now_ns, const Eigen::Vector3d& bias_B_rad_s) {
    started_ = true;
    last_ns_ = block_ns_ = now_ns;
    block_ = previous_ = since_ = Sums{};
    block_bias_B_rad_s_ = previous_bias_B_rad_s_ = since_bias_B_rad_s_ = bias_B_rad_s;
  }
  bool started() const { return started_; }
  //! A new bias block from `now_ns`, the bias estimate then `bias_B_rad_s`: the last block becomes the
  //! previous, the pull over the two is anchored at its start.
  void roll(std::int64_t now_ns, const Eigen::Vector3d& bias_B_rad_s) {
    previous_ = block_;
    block_ = Sums{};
    previous_bias_B_rad_s_ = block_bias_B_rad_s_;
    block_bias_B_rad_s_ = bias_B_rad_s;
    block_ns_ = now_ns;
  }
  std::int64_t block_ns() const { return block_ns_; }
  //! A reference update at `now_ns`: the attitude `q_RB` it corrected by `correction_B_rad` (body), the bias
  //! estimate `bias_B_rad_s` [rad/s] the attitude was propagated with since the last update.
  void add(std::int64_t now_ns, const Quaternion& q_RB, const Eigen::Vector3d& correction_B_rad,
           const Eigen::Vector3d& bias_B_rad_s) {
    if (!started_) return;
    const double dt_s = ns_to_seconds(now_ns - last_ns_);
    last_ns_ = now_ns;
    const Eigen::Matrix3d R = q_RB.toRotationMatrix();
    for (Sums* s : {&block_, &since_}) {
      s->correction_rad += R * correction_B_rad;
      s->bias_rad += R * bias_B_rad_s * dt_s;
      s->rotation_s += R * dt_s;
    }
  }
  //! [rad] |D| over this bias block and the last, against the bias estimate at the last one's start
  double blocks_rad() const {
    Sums both = previous_;
    both.correction_rad += block_.correction_rad;
    both.bias_rad += block_.bias_rad;
    both.rotation_s += block_.rotation_s;
    return both.pull_rad(previous_bias_B_rad_s_);
  }
  double since_rad() const { return since_.pull_rad(since_bias_B_rad_s_); }  //!< [rad] |D| since start()

 private:
  struct Sums {
    Eigen::Vector3d correction_rad = Eigen::Vector3d::Zero();  //!< [rad] Σ R·δθ
    Eigen::Vector3d bias_rad = Eigen::Vector3d::Zero();        //!< [rad] Σ R·b̂·Δt
    Eigen::Matrix3d rotation_s = Eigen::Matrix3d::Zero();      //!< [s] Σ R·Δt
    double pull_rad(const Eigen::Vector3d& bias0_B_rad_s) const {
      return (correction_rad - bias_rad + rotation_s * bias0_B_rad_s).norm();
    }
  };
  bool started_ = false;
  std::int64_t last_ns_ = 0;
  std::int64_t block_ns_ = -1;
  Sums block_, previous_, since_;
  Eigen::Vector3d block_bias_B_rad_s_ = Eigen::Vector3d::Zero();     //!< at the current block's start
  Eigen::Vector3d previous_bias_B_rad_s_ = Eigen::Vector3d::Zero();  //!< at the previous block's start
  Eigen::Vector3d since_bias_B_rad_s_ = Eigen::Vector3d::Zero();     //!< at the start
};

}  // namespace tetra::fdi::detail
