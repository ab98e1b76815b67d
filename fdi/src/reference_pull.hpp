#pragma once
// What the reference has pulled the attitude by, beyond the gyros (docs/fdi.md, "A common drift below the
// detectors"): the filter's attitude against the gyros' own propagation with the bias estimate b̂₀ of the
// last start. The two differ by every reference update's correction δθ and by the bias estimate's change
// integrated, D = Σ R(q̂)·δθ − Σ R(q̂)·(b̂ − b̂₀)·Δt in the reference frame (b̂ is constant between the
// updates that move it). Kept over the bias block the drift matches judge and the one before it (a drift
// that began before the block), and since the last start. When a mean innovation is matched as a drift of
// the gyros, the reference's bias is the other hypothesis the data leave standing: under it the attitude is
// off by the pull, which the protection level then covers (reference_budget.hpp).

#include <cstdint>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

class ReferencePull {
 public:
  //! Everything from `now_ns` on, against the gyros' propagation with the body-rate bias `bias_B_rad_s`.
  void start(std::int64_t now_ns, const Eigen::Vector3d& bias_B_rad_s) {
    started_ = true;
    last_ns_ = block_ns_ = now_ns;
    bias_start_B_rad_s_ = bias_B_rad_s;
    block_R_rad_.setZero();
    previous_R_rad_.setZero();
    total_R_rad_.setZero();
  }
  bool started() const { return started_; }
  //! A new bias block from `now_ns`: the last one becomes the previous.
  void roll(std::int64_t now_ns) {
    previous_R_rad_ = block_R_rad_;
    block_R_rad_.setZero();
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
    const Eigen::Vector3d d = q_RB * (correction_B_rad - (bias_B_rad_s - bias_start_B_rad_s_) * dt_s);
    block_R_rad_ += d;
    total_R_rad_ += d;
  }
  //! [rad] |D| over this bias block and the last
  double blocks_rad() const { return (previous_R_rad_ + block_R_rad_).norm(); }
  double total_rad() const { return total_R_rad_.norm(); }  //!< [rad] |D| since the start

 private:
  bool started_ = false;
  std::int64_t last_ns_ = 0;
  std::int64_t block_ns_ = -1;
  Eigen::Vector3d bias_start_B_rad_s_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d block_R_rad_ = Eigen::Vector3d::Zero();     //!< [rad] D over the current bias block
  Eigen::Vector3d previous_R_rad_ = Eigen::Vector3d::Zero();  //!< [rad] D over the one before
  Eigen::Vector3d total_R_rad_ = Eigen::Vector3d::Zero();     //!< [rad] D since the start
};

}  // namespace tetra::fdi::detail
