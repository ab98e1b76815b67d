#include "sim_dds_loop.hpp"

#include <iostream>

#include "cli_common.hpp"
#include "dds_common.hpp"
#include "sim_dds_link.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/sim/closed_loop_run.hpp"

namespace tetra::cli {

namespace {

constexpr const char* kName = "sim";
constexpr std::int64_t kLockstepTimeout_ns =
    2'000'000'000;  //!< [ns] give up waiting for one epoch's Attitude

//! The fusion service over DDS as the loop's estimator.
class DdsEstimator final : public sim::Estimator {
 public:
  DdsEstimator(SimDdsLink& link, bool lockstep, double speed)
      : link_(link), lockstep_(lockstep), speed_(speed) {}

  Result<sim::EstimatorOutput> estimate(const sim::SimEpoch& epoch) override {
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
  std::uint64_t missing() const { return missing_; }

 private:
  bool has(std::int64_t stamp_ns) const { return latest_ && latest_->stamp_ns >= stamp_ns; }
  Status take() {
    return link_.take_attitudes([&](const fdi::AttitudeEstimate& e) {
      if (!latest_ || e.stamp_ns > latest_->stamp_ns) latest_ = e;
    });
  }
  // Publishes epoch k at start + (stamp − first)/speed, taking attitudes while it waits.
  Status pace(std::int64_t stamp_ns) {
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

  SimDdsLink& link_;
  bool lockstep_;
  double speed_;
  std::uint64_t k_ = 0;
  std::uint64_t missing_ = 0;
  std::optional<fdi::AttitudeEstimate> latest_;
  std::optional<std::int64_t> first_stamp_ns_;
  std::int64_t start_ns_ = 0;
};

const dds::ShutdownSignal* g_shutdown = nullptr;

bool shutdown_requested() {
  return g_shutdown != nullptr && g_shutdown->requested();
}

}  // namespace

int sim_dds_closed_loop_main(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                             const ClosedLoopCliOptions& loop_options, const SimDdsOptions& dds_options) {
  if (Status st = check_closed_loop_options(scenario, loop_options, true); !st)
    return report(kName, st.error());
  auto simulator = sim::ClosedLoopSimulator::create(scenario, sim_options);
  if (!simulator) return report(kName, simulator.error());
  dds::ShutdownSignal shutdown;
  g_shutdown = &shutdown;
  const std::string unit = dds_options.unit.empty() ? scenario.unit.unit : dds_options.unit;
  auto link = SimDdsLink::open(unit, scenario.rate_hz, dds_options, &shutdown);
  if (!link) return report(kName, link.error());
  DdsEstimator estimator(**link, !loop_options.real_time, dds_options.speed);
  auto record = sim::run_closed_loop(*simulator, estimator, shutdown_requested);
  g_shutdown = nullptr;
  if (!record) return report(kName, record.error());
  record->fdi_events = false;  // the service's FdiEvent topic is not read here
  if (estimator.missing() > 0) {
    std::cout << "lockstep: " << estimator.missing() << " epochs without their Attitude within "
              << kLockstepTimeout_ns / 1'000'000'000 << " s (the loop went on with the latest)\n";
  }
  return write_closed_loop_outputs(scenario, *simulator, *record, loop_options);
}

}  // namespace tetra::cli
