// The run of `tetra demo` (tetra/dds_tools/demo_run.hpp).
#include "tetra/dds_tools/demo_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tetra/dds/loopback_config.hpp"
#include "tetra/dds_tools/child_process.hpp"
#include "tetra/dds_tools/demo.hpp"
#include "tetra/dds_tools/sim_dds.hpp"
#include "tetra/report/text.hpp"

namespace tetra::dds_tools {

namespace {

using report::fixed;

//! What the run showed, for the summary.
struct DemoOutcome {
  const sim::FaultSpec& fault;
  const std::string& fault_text;
  const DemoTimeline& timeline;
  const SimDdsScore& score;
  bool acknowledged = false;
  int fusion_status = -1;
};

void print_demo_summary(std::ostream& out, const DemoOutcome& r, const DemoOptions& o,
                        const std::string& dir) {
  const double fault_s = r.fault.at_s;
  const DemoTimeline& timeline = r.timeline;
  double before_deg = 0.0;
  double after_deg = 0.0;
  std::vector<std::pair<double, std::string>> modes;  // (time, "MODE gyros") at each change
  for (const auto& e : r.score.series) {
    const std::string mode = e.mode + " " + e.gyros;
    if (modes.empty() || modes.back().second != mode) modes.emplace_back(e.time_s, mode);
    if (e.time_s < fault_s) before_deg = std::max(before_deg, e.error_deg);
    if (timeline.reconfigured_s && e.time_s >= *timeline.reconfigured_s)
      after_deg = std::max(after_deg, e.error_deg);
  }
  const auto since_fault = [&](const std::optional<double>& t) {
    return t ? "t = " + fixed(*t, 2) + " s (" + fixed(*t - fault_s, 2) + " s after the fault)"
             : std::string("never");
  };
  out << "\nsummary\n"
      << "  fault injected:    " << r.fault_text << '\n'
      << "  detected:          " << since_fault(timeline.detected_s) << '\n'
      << "  isolated:          " << since_fault(timeline.isolated_s);
  if (timeline.isolated_gyro)
    out << ": gyro " << *timeline.isolated_gyro << " (" << timeline.isolated_kind << ")";
  out << "\n  reconfigured:      " << since_fault(timeline.reconfigured_s);
  if (timeline.reconfigured_s) out << " to gyros " << timeline.reconfigured_gyros;
  out << "\n  mode changes:     ";
  for (const auto& [t, mode] : modes) out << " " << mode << " @" << fixed(t, 2) << "s";
  out << "\n  attitude epochs:   " << r.score.attitudes_scored << " received of " << r.score.epochs_published
      << " published\n"
      << "  attitude error:    worst before the fault " << fixed(before_deg * 3600.0, 1) << " arcsec; ";
  if (timeline.reconfigured_s)
    out << "worst after reconfiguration " << fixed(after_deg * 3600.0, 1) << " arcsec; ";
  out << "at the end " << fixed(r.score.series.empty() ? 0.0 : r.score.series.back().error_deg * 3600.0, 1)
      << " arcsec\n"
      << "  operator command:  reinstate " << r.fault.gyro
      << (r.acknowledged ? ", acknowledged" : ", NOT acknowledged") << '\n'
      << "  service:           exit status " << r.fusion_status << " after SIGTERM"
      << (o.keep_dir.empty() ? std::string(" (its log: --keep DIR)") : " (log " + dir + "/fusion.log)")
      << '\n';
}

//! After the run: the late joiner's view (`tetra monitor --once`), then the operator reinstates the failed
//! gyro (`tetra command`); true if the service acknowledged it.
bool after_the_demo(std::ostream& out, const DemoOptions& o, const std::string& unit, int gyro) {
  const std::string domain_text = std::to_string(o.domain);
  out << "\nmonitor view after the run (tetra monitor --once; the simulator has stopped, so its gyros are "
         "absent and the unit LOST; the event history is the late joiner's):\n"
      << std::flush;
  ChildProcess monitor(
      spawn_self({"monitor", "--once", "--unit", unit, "--domain", domain_text, "--timeout", "5"}));
  monitor.wait();
  // The operator's side: reinstate the failed gyro; the service obeys and acknowledges it as an event.
  const std::string gyro_text = std::to_string(gyro);
  out << "\noperator: tetra command --unit " << unit << " reinstate " << gyro_text << '\n' << std::flush;
  ChildProcess command(spawn_self(
      {"command", "--unit", unit, "reinstate", gyro_text, "--domain", domain_text, "--timeout", "5"}));
  return command.wait() == 0;
}

void print_demo_banner(std::ostream& out, const DemoOptions& o, const sim::Simulator& simulator,
                       const std::string& dir) {
  out << "tetra demo: domain " << o.domain << " (loopback only), unit " << simulator.scenario().unit.unit
      << ", scenario " << simulator.scenario().name << ", " << fixed(o.seconds, 0) << " s at "
      << fixed(o.rate_hz, 0) << " Hz, " << fixed(o.speed, 1) << "x real time\n"
      << "  fault: " << o.fault_text << "\n  the service: tetra fusion --config " << dir << "/fusion.yaml\n"
      << std::flush;
}

//! The ground station (--web) as a child process; pid -1 without --web.
int start_demo_ground(std::ostream& out, const DemoOptions& o, const std::string& dir) {
  if (!o.web) return -1;
  const int pid = spawn_self({"ground", "--listen", o.listen, "--domain", std::to_string(o.domain)},
                             dir + "/ground.log", dir + "/ground.log");
  if (pid > 0) {
    out << "  ground station: http://" << o.listen << "/  (open it in a browser; log " << dir
        << "/ground.log)\n"
        << std::flush;
  }
  return pid;
}

}  // namespace

Result<bool> run_demo(const DemoOptions& o, const sim::FaultSpec& fault, dds::ShutdownSignal& shutdown,
                      std::ostream& out) {
  setenv("CYCLONEDDS_URI", dds::kLoopbackConfigXml, 1);  // private loopback domain, children included
  sim::SimEpoch first;
  auto simulator = demo_simulator({o.scenario_name, o.seconds, o.rate_hz, o.seed}, fault, first);
  if (!simulator) return simulator.error();
  auto dir = demo_folder(o.keep_dir);
  if (!dir) return dir.error();
  if (auto s = write_demo_service_files(*dir, *simulator, first, o.rate_hz); !s) return s.error();

  print_demo_banner(out, o, *simulator, *dir);
  ChildProcess fusion(
      spawn_self({"fusion", "--config", *dir + "/fusion.yaml", "--domain", std::to_string(o.domain)},
                 *dir + "/fusion.log", *dir + "/fusion.log"));
  if (fusion.pid() <= 0) return failure("cannot start tetra fusion");
  out << "  service pid " << fusion.pid() << '\n';
  ChildProcess ground(start_demo_ground(out, o, *dir));
  if (o.web && ground.pid() <= 0) return failure("cannot start tetra ground");
  auto watch = DemoWatch::open(o.domain, simulator->gyro_count(), out);
  if (!watch) return watch.error();

  SimDdsOptions sim_options;
  sim_options.domain = o.domain;
  sim_options.speed = o.speed;
  sim_options.wait_readers = 1;  // the service
  auto score = run_sim_dds(*simulator, sim_options, &shutdown, [&](const SimDdsScore& progress) {
    const bool scored = !progress.series.empty();
    watch->print_progress(scored ? progress.series.back().time_s : 0.0,
                          scored ? std::optional(progress.series.back().error_deg) : std::nullopt);
  });
  if (!score) {
    fusion.stop();
    return failure(score.error().message + " (service log: " + *dir + "/fusion.log)");
  }
  watch->take();
  const bool acknowledged = after_the_demo(out, o, simulator->scenario().unit.unit, fault.gyro);
  print_demo_summary(out, {fault, o.fault_text, watch->timeline(), *score, acknowledged, fusion.stop()}, o,
                     *dir);
  if (o.web && !shutdown.requested()) {
    out << "\nthe ground station stays up at http://" << o.listen
        << "/ (the service has stopped: it shows SERVICE LOST); Ctrl-C to end\n"
        << std::flush;
    while (!shutdown.requested()) usleep(100'000);  // no DDS entity left to wait on
  }
  ground.stop();
  if (o.keep_dir.empty()) std::filesystem::remove_all(*dir);
  const bool ok = watch->timeline().isolated_s && score->attitudes_scored > 0;
  return ok || shutdown.requested();
}

}  // namespace tetra::dds_tools
