// `target: dds` campaigns (tetra/campaign/dds_estimators.hpp).
#include "tetra/campaign/dds_estimators.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <spdlog/fmt/fmt.h>

#include "tetra/core/calibration_file.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/dds_tools/child_process.hpp"
#include "tetra/dds_tools/sim_dds_estimator.hpp"
#include "tetra/dds_tools/sim_dds_link.hpp"

namespace tetra::dds_tools {

using dds::monotonic_ns;

namespace {

// Lockstep is not paced: the service's wall-clock limits only need to outlast the stalls of a loaded
// machine (2 cores shared with builds: 20 ms, the default max_latency_s, is not enough). An epoch
// waits up to kMaxLatency_s for its last sample (a sample later than that changes the epoch: the run
// fails); a gyro that stops (a dropout fault) is declared absent after kDeadline_s, and its epochs are
// no longer held. The service's `speed` gives that deadline: 3 sample periods / speed.
constexpr double kMaxLatency_s = 0.5;
constexpr double kDeadline_s = 2.0;
double service_speed(double rate_hz) {
  return 3.0 / (rate_hz * kDeadline_s);
}
constexpr double kServiceStart_s = 30.0;                        //!< [s] for the service to hear the campaign
constexpr std::int64_t kLastEventsTimeout_ns = 10'000'000'000;  //!< [ns] for its last Health and events
constexpr auto kPollPeriod = std::chrono::milliseconds(2);

//! The files of one run's service: configuration, calibration, log.
struct ServiceFiles {
  std::string config;
  std::string calibration;
  std::string log;
  void remove() const {
    std::error_code ec;
    for (const std::string& f : {config, calibration, log}) std::filesystem::remove(f, ec);
  }
};

//! The service's configuration: the scenario's unit under `unit`, the spec's pipeline starting at
//! `initial_q_RB`.
Result<ServiceFiles> write_service_files(const sim::CampaignSpec& spec, const sim::Scenario& sc,
                                         const std::string& unit, const Quaternion& initial_q_RB,
                                         const std::string& work_dir) {
  const std::filesystem::path dir(work_dir);
  ServiceFiles files{(dir / (unit + ".yaml")).string(), (dir / (unit + "_cal.yaml")).string(),
                     (dir / (unit + ".log")).string()};
  Calibration cal = sc.unit;
  cal.unit = unit;
  if (Status st = write_calibration(files.calibration, cal); !st) return st.error();
  std::string pipeline;
  std::istringstream lines(sim::pipeline_yaml_from(spec, initial_q_RB));
  for (std::string line; std::getline(lines, line);) pipeline += "  " + line + "\n";
  std::ofstream out(files.config);
  out << "unit: " << unit << "\ncalibration: " << std::filesystem::path(files.calibration).filename().string()
      << "\nsample_rate_hz: " << fmt::format("{}", sc.rate_hz)
      << "\nspeed: " << fmt::format("{}", service_speed(sc.rate_hz)) << "\nmax_latency_s: " << kMaxLatency_s
      << "\nhealth_period_s: 0.05\npipeline:\n"
      << pipeline;
  if (!out) return failure(files.config + ": cannot write");
  return files;
}

//! A spawned `tetra fusion`: stopped (SIGTERM) and reaped when this goes.
class ServiceProcess {
 public:
  explicit ServiceProcess(int pid) : pid_(pid) {}
  ServiceProcess(const ServiceProcess&) = delete;
  ServiceProcess& operator=(const ServiceProcess&) = delete;
  ~ServiceProcess() { (void)stop(); }
  //! True when it ended cleanly.
  bool stop() {
    if (pid_ <= 0) return false;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
  }

 private:
  int pid_;
};

//! One run against its own service.
class ServiceEstimator final : public sim::Estimator {
 public:
  ServiceEstimator(ServiceFiles files, int pid) : files_(std::move(files)), process_(pid) {}
  ~ServiceEstimator() override {
    process_.stop();
    if (succeeded_) files_.remove();
  }
  ServiceEstimator(const ServiceEstimator&) = delete;
  ServiceEstimator& operator=(const ServiceEstimator&) = delete;

  Status open(const std::string& unit, const sim::Scenario& sc, int domain);
  Result<sim::EstimatorOutput> estimate(const sim::SimEpoch& epoch) override {
    last_stamp_ns_ = epoch.stamp_ns;
    if (Status st = take_events(); !st) return st.error();
    return lockstep_->estimate(epoch);
  }
  Status finish(std::vector<fdi::FdiEvent>& events) override;

 private:
  Status take_events();
  std::string log_hint() const { return " (service log: " + files_.log + ")"; }

  ServiceFiles files_;
  ServiceProcess process_;
  std::string unit_;
  std::unique_ptr<SimDdsLink> link_;
  std::optional<DdsEstimator> lockstep_;
  std::optional<dds::Reader<tetra_FdiEvent2>> event_reader_;
  std::optional<dds::Reader<tetra_Health>> health_reader_;
  std::map<std::uint64_t, fdi::FdiEvent> events_;  //!< pipeline events by event_seq
  std::uint64_t acks_ = 0;                         //!< command acknowledgements seen (none expected)
  std::int64_t last_stamp_ns_ = 0;
  bool succeeded_ = false;
};

Status ServiceEstimator::open(const std::string& unit, const sim::Scenario& sc, int domain) {
  unit_ = unit;
  SimDdsOptions options;
  options.domain = static_cast<dds_domainid_t>(domain);
  options.unit = unit;
  // The gyro writer offers a deadline 1 % shorter than the service requests (offered <= requested, or
  // DDS does not match them; both are computed from the speed, rounded to nanoseconds their own way).
  options.speed = service_speed(sc.rate_hz) * 1.01;
  options.wait_timeout_s = kServiceStart_s;
  auto link = SimDdsLink::open(unit, sc.rate_hz, options, nullptr);
  if (!link) return failure("the service of unit " + unit + ": " + link.error().message + log_hint());
  link_ = std::move(link.value());
  auto events =
      dds::Reader<tetra_FdiEvent2>::create(link_->participant(), link_->topics().event, dds::event_qos());
  if (!events) return events.error();
  event_reader_ = std::move(events.value());
  auto health =
      dds::Reader<tetra_Health>::create(link_->participant(), link_->topics().health, dds::health_qos());
  if (!health) return health.error();
  health_reader_ = std::move(health.value());
  lockstep_.emplace(*link_, true, options.speed);
  return ok_status();
}

Status ServiceEstimator::take_events() {
  auto taken = event_reader_->take([&](const tetra_FdiEvent2& msg, const dds_sample_info_t&) {
    if (dds::from_wire(msg.unit) != unit_) return;
    dds::EventView view = dds::from_wire(msg);
    if (view.command_id != 0) {
      ++acks_;
      return;
    }
    events_.emplace(view.event_seq, std::move(view.event));
  });
  if (!taken) return taken.error();
  return ok_status();
}

Status ServiceEstimator::finish(std::vector<fdi::FdiEvent>& events) {
  if (lockstep_->missing() > 0)
    return failure(fmt::format("unit {}: {} epochs without their Attitude within {} s{}", unit_,
                               lockstep_->missing(), DdsEstimator::kLockstepTimeout_ns / 1'000'000'000,
                               log_hint()));
  // Complete when a Health of the last epoch has come and every event it counts has been read.
  const std::int64_t give_up = monotonic_ns() + kLastEventsTimeout_ns;
  std::optional<std::uint64_t> published;
  std::uint64_t late = 0;
  for (;;) {
    auto taken = health_reader_->take([&](const tetra_Health& msg, const dds_sample_info_t&) {
      const dds::HealthView view = dds::from_wire(msg);
      if (view.unit == unit_ && view.health.stamp_ns >= last_stamp_ns_) {
        published = view.events_published;
        late = view.counters.samples_late + view.counters.references_late;
      }
    });
    if (!taken) return taken.error();
    if (Status st = take_events(); !st) return st;
    if (published && events_.size() + acks_ >= *published) break;
    if (monotonic_ns() >= give_up)
      return failure(fmt::format("unit {}: {} of {} FdiEvents received{}", unit_, events_.size() + acks_,
                                 published ? std::to_string(*published) : "?", log_hint()));
    std::this_thread::sleep_for(kPollPeriod);
  }
  if (late > 0)
    return failure(
        fmt::format("unit {}: {} samples or references reached the service after their epoch "
                    "(a stall longer than its max_latency_s): not the run simulated{}",
                    unit_, late, log_hint()));
  for (auto& [seq, event] : events_) events.push_back(std::move(event));
  if (!process_.stop()) return failure("unit " + unit_ + ": the service did not end cleanly" + log_hint());
  succeeded_ = true;
  return ok_status();
}

}  // namespace

}  // namespace tetra::dds_tools

namespace tetra::campaign {

sim::EstimatorFactory dds_campaign_estimators(const sim::CampaignSpec& spec, const std::string& work_dir) {
  return [&spec, work_dir](const sim::Scenario& sc, const sim::CampaignCase& c,
                           const Quaternion& initial_q_RB) -> Result<std::unique_ptr<sim::Estimator>> {
    const std::string unit = fmt::format("campaign-{}-{}", ::getpid(), c.index);
    auto files = dds_tools::write_service_files(spec, sc, unit, initial_q_RB, work_dir);
    if (!files) return files.error();
    const int pid = dds_tools::spawn_self({"fusion", "--config", files->config, "--domain",
                                           std::to_string(spec.dds_domain), "--log-level", "warn"},
                                          files->log, files->log);
    if (pid < 0) return failure("cannot start `tetra fusion` for run " + std::to_string(c.index));
    auto estimator = std::make_unique<dds_tools::ServiceEstimator>(std::move(files.value()), pid);
    if (Status st = estimator->open(unit, sc, spec.dds_domain); !st) return st.error();
    return std::unique_ptr<sim::Estimator>(std::move(estimator));
  };
}

}  // namespace tetra::campaign
