#pragma once
// The parts of `tetra demo` (docs/dds.md) that are not the command line's: the simulated unit with the
// injected fault, the fusion service's files, and the monitor's side (Health and events printed as they
// come, the timeline of the fault's detection, isolation and reconfiguration).

#include <optional>
#include <ostream>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::dds_tools {

struct DemoSimulation {
  std::string scenario = "orbit";  //!< static, lab-orbit, orbit, slews or a scenario file
  double seconds = 40.0;           //!< [s] simulated duration
  double rate_hz = 50.0;           //!< [Hz] gyro rate
  std::uint64_t seed = 1;
};

//! Error::subject of a fault that does not fit the run.
inline constexpr const char* kSubjectFault = "fault";

//! The simulated unit with the injected fault, and its first epoch (for the service's initial attitude).
Result<sim::Simulator> demo_simulator(const DemoSimulation& options, const sim::FaultSpec& fault,
                                      sim::SimEpoch& first);

//! The service's files in `dir`: the simulated unit's as-built calibration (calibration.yaml), and a
//! configuration (fusion.yaml) starting from its initial attitude.
Status write_demo_service_files(const std::string& dir, const sim::Simulator& simulator,
                                const sim::SimEpoch& first, double rate_hz);

//! The folder of the service's files: `keep_dir` (created), or a temporary one.
Result<std::string> demo_folder(const std::string& keep_dir);

//! When the fault was detected, isolated and reconfigured [s], as the events told.
struct DemoTimeline {
  std::optional<double> detected_s, isolated_s, reconfigured_s;
  std::optional<int> isolated_gyro;
  std::string isolated_kind;
  std::string reconfigured_gyros;
};

//! The monitor's side, in this process: Health and events (printed on `out` as they come), and the
//! timeline.
class DemoWatch {
 public:
  static Result<DemoWatch> open(dds_domainid_t domain, int n_gyros, std::ostream& out) {
    auto session = dds::Session::open(domain);
    if (!session) return session.error();
    auto health = session->reader<tetra_Health>(dds::health_qos());
    if (!health) return health.error();
    auto event = session->reader<tetra_FdiEvent2>(dds::event_qos());
    if (!event) return event.error();
    return DemoWatch(std::move(session).value(), std::move(health).value(), std::move(event).value(), n_gyros,
                     out);
  }
  //! Takes the Health and events received.
  void take();
  //! One progress line at simulated time `time_s`: the latest Health and the attitude error (if scored).
  void print_progress(double time_s, std::optional<double> error_deg);
  const DemoTimeline& timeline() const { return timeline_; }

 private:
  DemoWatch(dds::Session session, dds::Reader<tetra_Health> health, dds::Reader<tetra_FdiEvent2> event, int n,
            std::ostream& out)
      : session_(std::move(session)),
        health_reader_(std::move(health)),
        event_reader_(std::move(event)),
        n_(n),
        out_(out) {}
  void on_event(const fdi::FdiEvent& e);

  dds::Session session_;
  dds::Reader<tetra_Health> health_reader_;
  dds::Reader<tetra_FdiEvent2> event_reader_;
  int n_;
  std::ostream& out_;
  DemoTimeline timeline_;
  std::optional<dds::HealthView> health_;
};

}  // namespace tetra::dds_tools
