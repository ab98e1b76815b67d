#pragma once
// A `tetra fusion` service over DDS as the estimator of a simulated run (closed loop and campaigns
// over DDS). Each epoch's samples are published on the link; then
//   lockstep   wait (up to 2 s) for that epoch's Attitude: the same numbers as the pipeline in process
//   real time  publish at the wall-clock rate (`speed`) and return the newest Attitude received
// The estimate returned is the newest Attitude received so far.

#include <cstdint>
#include <optional>

#include "tetra/dds_tools/sim_dds_link.hpp"
#include "tetra/sim/closed_loop_run.hpp"

namespace tetra::dds_tools {

class DdsEstimator final : public sim::Estimator {
 public:
  //! [ns] how long lockstep waits for one epoch's Attitude before going on with the newest.
  static constexpr std::int64_t kLockstepTimeout_ns = 2'000'000'000;

  DdsEstimator(SimDdsLink& link, bool lockstep, double speed)
      : link_(link), lockstep_(lockstep), speed_(speed) {
    if (lockstep_) link_.require_one_attitude_writer();  // a second service would mix into the run
  }

  Result<sim::EstimatorOutput> estimate(const sim::SimEpoch& epoch) override;
  //! Lockstep epochs whose Attitude did not come within the timeout.
  std::uint64_t missing() const { return missing_; }

 private:
  bool has(std::int64_t stamp_ns) const { return latest_ && latest_->stamp_ns >= stamp_ns; }
  Status take();
  //! Publishes epoch k at start + (stamp − first)/speed, taking attitudes while it waits.
  Status pace(std::int64_t stamp_ns);

  SimDdsLink& link_;
  bool lockstep_;
  double speed_;
  std::uint64_t k_ = 0;
  std::uint64_t missing_ = 0;
  std::optional<fdi::AttitudeEstimate> latest_;
  std::optional<std::int64_t> first_stamp_ns_;
  std::int64_t start_ns_ = 0;
};

}  // namespace tetra::dds_tools
