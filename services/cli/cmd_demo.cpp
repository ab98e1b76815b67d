// tetra demo — simulator + fusion service + monitor on a private loopback DDS domain, a gyro
// failure injected mid-run, and a summary (docs/dds.md). The simulator runs in this process (it
// scores the attitude it receives against its truth); the service is a separate `tetra fusion`
// process; the monitor's view is printed once a second and, at the end, by `tetra monitor --once`.
// With --web, a `tetra ground` process serves the ground station in the browser (docs/ground.md)
// and stays up after the summary until SIGINT/SIGTERM.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "sim_dds.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/json.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/loopback_config.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds_tools/child_process.hpp"
#include "tetra/dds_tools/demo.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::cli {

namespace {

struct DemoOptions {
  std::string scenario_name = "orbit";
  std::string fault_text = "gyro=2,kind=stuck,at=15";
  double seconds = 40.0;
  double rate_hz = 50.0;
  double speed = 2.0;
  std::uint64_t seed = 1;
  std::string keep_dir;
  bool web = false;
  std::string listen = "127.0.0.1:8080";
  dds_domainid_t domain = static_cast<dds_domainid_t>(150 + getpid() % 80);
};

void add_demo_options(CLI::App& app, DemoOptions& o) {
  app.add_option("--scenario", o.scenario_name,
                 "simulated motion: static, lab-orbit, orbit, slews or FILE.yaml")
      ->capture_default_str();
  app.add_option("--fault", o.fault_text, "the injected failure (docs/interfaces.md §2.7)")
      ->capture_default_str();
  app.add_option("--seconds", o.seconds, "[s] simulated duration")
      ->check(CLI::Range(5.0, 600.0))
      ->capture_default_str();
  app.add_option("--rate-hz", o.rate_hz, "[Hz] gyro rate")
      ->check(CLI::Range(1.0, 2000.0))
      ->capture_default_str();
  app.add_option("--speed", o.speed, "times faster than real time")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  app.add_option("--seed", o.seed, "simulation seed")->capture_default_str();
  app.add_option("--keep", o.keep_dir, "keep the service's configuration and log in this folder");
  app.add_flag("--web", o.web, "also run the ground station in the browser (tetra ground) and print its URL");
  app.add_option("--listen", o.listen, "--web: HOST:PORT of the ground station")->capture_default_str();
  app.add_option("--domain", o.domain, "DDS domain id (default: 150 + pid % 80, private to this run)")
      ->check(CLI::Range(0, 232));
}

//! What the run showed, for the summary.
struct DemoOutcome {
  const sim::FaultSpec& fault;
  const std::string& fault_text;
  const dds_tools::DemoTimeline& timeline;
  const SimDdsScore& score;
  bool acknowledged = false;
  int fusion_status = -1;
};

void print_summary(const DemoOutcome& r, const DemoOptions& o, const std::string& dir) {
  const double fault_s = r.fault.at_s;
  const dds_tools::DemoTimeline& timeline = r.timeline;
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
  std::cout << "\nsummary\n"
            << "  fault injected:    " << r.fault_text << '\n'
            << "  detected:          " << since_fault(timeline.detected_s) << '\n'
            << "  isolated:          " << since_fault(timeline.isolated_s);
  if (timeline.isolated_gyro)
    std::cout << ": gyro " << *timeline.isolated_gyro << " (" << timeline.isolated_kind << ")";
  std::cout << "\n  reconfigured:      " << since_fault(timeline.reconfigured_s);
  if (timeline.reconfigured_s) std::cout << " to gyros " << timeline.reconfigured_gyros;
  std::cout << "\n  mode changes:     ";
  for (const auto& [t, mode] : modes) std::cout << " " << mode << " @" << fixed(t, 2) << "s";
  std::cout << "\n  attitude epochs:   " << r.score.attitudes_scored << " received of "
            << r.score.epochs_published << " published\n"
            << "  attitude error:    worst before the fault " << fixed(before_deg * 3600.0, 1) << " arcsec; ";
  if (timeline.reconfigured_s)
    std::cout << "worst after reconfiguration " << fixed(after_deg * 3600.0, 1) << " arcsec; ";
  std::cout << "at the end "
            << fixed(r.score.series.empty() ? 0.0 : r.score.series.back().error_deg * 3600.0, 1)
            << " arcsec\n"
            << "  operator command:  reinstate " << r.fault.gyro
            << (r.acknowledged ? ", acknowledged" : ", NOT acknowledged") << '\n'
            << "  service:           exit status " << r.fusion_status << " after SIGTERM"
            << (o.keep_dir.empty() ? std::string(" (its log: --keep DIR)") : " (log " + dir + "/fusion.log)")
            << '\n';
}

//! After the run: the late joiner's view (`tetra monitor --once`), then the operator reinstates the failed
//! gyro (`tetra command`); true if the service acknowledged it.
bool after_the_run(const DemoOptions& o, const std::string& unit, int gyro) {
  const std::string domain_text = std::to_string(o.domain);
  std::cout
      << "\nmonitor view after the run (tetra monitor --once; the simulator has stopped, so its gyros are "
         "absent and the unit LOST; the event history is the late joiner's):\n"
      << std::flush;
  dds_tools::ChildProcess monitor(dds_tools::spawn_self(
      {"monitor", "--once", "--unit", unit, "--domain", domain_text, "--timeout", "5"}));
  monitor.wait();
  // The operator's side: reinstate the failed gyro; the service obeys and acknowledges it as an event.
  const std::string gyro_text = std::to_string(gyro);
  std::cout << "\noperator: tetra command --unit " << unit << " reinstate " << gyro_text << '\n'
            << std::flush;
  dds_tools::ChildProcess command(dds_tools::spawn_self(
      {"command", "--unit", unit, "reinstate", gyro_text, "--domain", domain_text, "--timeout", "5"}));
  return command.wait() == 0;
}

void print_banner(const DemoOptions& o, const sim::Simulator& simulator, const std::string& dir) {
  std::cout << "tetra demo: domain " << o.domain << " (loopback only), unit "
            << simulator.scenario().unit.unit << ", scenario " << simulator.scenario().name << ", "
            << fixed(o.seconds, 0) << " s at " << fixed(o.rate_hz, 0) << " Hz, " << fixed(o.speed, 1)
            << "x real time\n"
            << "  fault: " << o.fault_text << "\n  the service: tetra fusion --config " << dir
            << "/fusion.yaml\n"
            << std::flush;
}

//! The ground station (--web) as a child process; pid -1 without --web.
int start_ground(const DemoOptions& o, const std::string& dir) {
  if (!o.web) return -1;
  const int pid =
      dds_tools::spawn_self({"ground", "--listen", o.listen, "--domain", std::to_string(o.domain)},
                            dir + "/ground.log", dir + "/ground.log");
  if (pid > 0) {
    std::cout << "  ground station: http://" << o.listen << "/  (open it in a browser; log " << dir
              << "/ground.log)\n"
              << std::flush;
  }
  return pid;
}

}  // namespace

int cmd_demo(int argc, char** argv) {
  dds::ShutdownSignal shutdown;
  CLI::App app{
      "Simulator + fusion service + monitor on a private loopback DDS domain, with a gyro failure "
      "injected mid-run, and a summary. Takes about 20 s (--seconds / --speed).",
      "demo"};
  DemoOptions o;
  add_demo_options(app, o);
  if (auto exit = parse(app, argc, argv)) return *exit;
  setenv("CYCLONEDDS_URI", dds::kLoopbackConfigXml, 1);  // private loopback domain, children included

  auto fault = sim::parse_fault_spec(o.fault_text);
  if (!fault) return report("demo", fault.error());
  sim::SimEpoch first;
  auto simulator = dds_tools::demo_simulator({o.scenario_name, o.seconds, o.rate_hz, o.seed}, *fault, first);
  if (!simulator)
    return report("demo", simulator.error(), {{dds_tools::kSubjectFault, "--fault: {message}"}});
  auto dir = dds_tools::demo_folder(o.keep_dir);
  if (!dir) return report("demo", dir.error());
  if (auto s = dds_tools::write_demo_service_files(*dir, *simulator, first, o.rate_hz); !s)
    return report("demo", s.error());

  print_banner(o, *simulator, *dir);
  dds_tools::ChildProcess fusion(dds_tools::spawn_self(
      {"fusion", "--config", *dir + "/fusion.yaml", "--domain", std::to_string(o.domain)},
      *dir + "/fusion.log", *dir + "/fusion.log"));
  if (fusion.pid() <= 0) return report("demo", failure("cannot start tetra fusion"));
  std::cout << "  service pid " << fusion.pid() << '\n';
  dds_tools::ChildProcess ground(start_ground(o, *dir));
  if (o.web && ground.pid() <= 0) return report("demo", failure("cannot start tetra ground"));
  auto watch = dds_tools::DemoWatch::open(o.domain, simulator->gyro_count(), std::cout);
  if (!watch) return report("demo", watch.error());

  SimDdsOptions sim_options;
  sim_options.enabled = true;
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
    return report("demo", failure(score.error().message + " (service log: " + *dir + "/fusion.log)"));
  }
  watch->take();
  const bool acknowledged = after_the_run(o, simulator->scenario().unit.unit, fault->gyro);
  print_summary({*fault, o.fault_text, watch->timeline(), *score, acknowledged, fusion.stop()}, o, *dir);
  if (o.web && !shutdown.requested()) {
    std::cout << "\nthe ground station stays up at http://" << o.listen
              << "/ (the service has stopped: it shows SERVICE LOST); Ctrl-C to end\n"
              << std::flush;
    while (!shutdown.requested()) usleep(100'000);  // no DDS entity left to wait on
  }
  ground.stop();
  if (o.keep_dir.empty()) std::filesystem::remove_all(*dir);
  const bool ok = watch->timeline().isolated_s && score->attitudes_scored > 0;
  return ok || shutdown.requested() ? kExitOk : kExitFailure;
}

}  // namespace tetra::cli
