#include "tetra/dds_tools/sim_dds_estimator.hpp"

#include "tetra/dds/clock.hpp"

namespace tetra::dds_tools {

using dds::monotonic_ns;

Result<sim::EstimatorOutput> DdsEstimator::estimate(const sim::SimEpoch& epoch) {
  if (!lockstep_) {
    if (Status s = pace(epoch.stamp_ns); !s) return s.error();
  }
  if (Status s = link_.publish(epoch, ++k_); !s) return s.error();
  if (Status s = take(); !s) return s.error();
  if (lockstep_) {
    const std::int64_t give_up = monotonic_ns() + kLockstepTimeout_ns;
    while (!has(epoch.stamp_ns) && monotonic_ns() < give_up && !link_.stop_requested()) {
      if (Status s = link_.wait_until(give_up); !s) return s.error();
      if (Status s = take(); !s) return s.error();
    }
    if (!has(epoch.stamp_ns)) ++missing_;
  }
  sim::EstimatorOutput out;
  out.latest = latest_;
  return out;
}

Status DdsEstimator::take() {
  return link_.take_attitudes([&](const fdi::AttitudeEstimate& e) {
    if (!latest_ || e.stamp_ns > latest_->stamp_ns) latest_ = e;
  });
}

Status DdsEstimator::pace(std::int64_t stamp_ns) {
  if (speed_ <= 0.0) return ok_status();
  if (!first_stamp_ns_) {
    first_stamp_ns_ = stamp_ns;
    start_ns_ = monotonic_ns();
  }
  const auto due =
      start_ns_ + static_cast<std::int64_t>(static_cast<double>(stamp_ns - *first_stamp_ns_) / speed_);
  for (std::int64_t now = monotonic_ns(); now < due && !link_.stop_requested(); now = monotonic_ns()) {
    if (Status s = link_.wait_until(due); !s) return s;
    if (Status s = take(); !s) return s;
  }
  return ok_status();
}

}  // namespace tetra::dds_tools
