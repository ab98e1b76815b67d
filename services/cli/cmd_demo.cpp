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
#include "tetra/sim/fault.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::cli {

namespace {

//! A child process, terminated (SIGTERM, then SIGKILL) when this goes out of scope.
class Child {
 public:
  explicit Child(int pid) : pid_(pid) {}
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() { stop(); }
  int pid() const { return pid_; }
  //! SIGTERM, wait up to `grace_ms`, then SIGKILL. Returns the exit status (-1 if killed).
  int stop(int grace_ms = 3000) {
    if (pid_ <= 0) return status_;
    kill(pid_, SIGTERM);
    for (int waited = 0; waited < grace_ms; waited += 10) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        return status_;
      }
      usleep(10'000);  // a child's exit cannot be put on a DDS waitset
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
    return status_;
  }
  //! Waits for a child that ends by itself.
  int wait() {
    if (pid_ <= 0) return status_;
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return status_;
  }

 private:
  int pid_ = -1;
  int status_ = -1;
};

struct Timeline {
  std::optional<double> detected_s, isolated_s, reconfigured_s;
  std::optional<int> isolated_gyro;
  std::string isolated_kind;
  std::string reconfigured_gyros;
};

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

//! The simulated unit with the injected fault, and its first epoch (for the service's initial attitude).
Result<sim::Simulator> demo_simulator(const DemoOptions& o, const sim::FaultSpec& fault,
                                      sim::SimEpoch& first) {
  auto scenario = std::filesystem::exists(o.scenario_name) ? sim::read_scenario(o.scenario_name)
                                                           : sim::builtin_scenario(o.scenario_name);
  if (!scenario) return scenario.error();
  scenario->duration_s = o.seconds;
  scenario->rate_hz = o.rate_hz;
  if (fault.at_s >= o.seconds) return bad_input("--fault: at=" + fixed(fault.at_s, 1) + " is after the end");
  sim::SimOptions options;
  options.seed = o.seed;
  options.faults.push_back(fault);
  auto simulator = sim::Simulator::create(*scenario, options);
  if (!simulator) return simulator.error();
  if (!simulator->next(first)) return bad_input("the scenario has no epochs");
  simulator->reset();
  return simulator;
}

//! The service's files in `dir`: the simulated unit's as-built calibration, and a configuration starting
//! from its initial attitude.
Status write_service_files(const std::string& dir, const sim::Simulator& simulator,
                           const sim::SimEpoch& first, double rate_hz) {
  const std::string& unit = simulator.scenario().unit.unit;
  if (auto s = write_calibration(dir + "/calibration.yaml", simulator.scenario().unit); !s) return s;
  const auto q = to_wxyz(first.truth_q_RB);
  std::string unit_text;
  append_json_string(unit_text, unit);  // a JSON string is a YAML double-quoted scalar: any name reads back
  std::ostringstream config;
  config << "# tetra demo: fusion service configuration\n"
         << "unit: " << unit_text << "\ncalibration: calibration.yaml\n"
         << "sample_rate_hz: " << rate_hz << "\n"
         << "max_latency_s: 0.05\nhealth_period_s: 0.5\n"
         << "pipeline:\n  initial_q_wxyz: [" << json_number(q[0]) << ", " << json_number(q[1]) << ", "
         << json_number(q[2]) << ", " << json_number(q[3]) << "]\n"
         << "  sample_period_s: " << json_number(1.0 / rate_hz) << '\n';
  return write_text_file(dir + "/fusion.yaml", config.str());
}

//! The folder of the service's files: --keep's, or a temporary one.
Result<std::string> demo_folder(const std::string& keep_dir) {
  std::string dir = keep_dir;
  if (dir.empty()) {
    char tmpl[] = "/tmp/tetra-demo-XXXXXX";
    if (mkdtemp(tmpl) == nullptr) return failure("cannot create a temporary folder");
    dir = tmpl;
  }
  std::filesystem::create_directories(dir);
  return dir;
}

//! The monitor's side, in this process: Health and events, printed as they come, and the timeline of
//! the fault's detection, isolation and reconfiguration.
class DemoWatch {
 public:
  static Result<DemoWatch> open(dds_domainid_t domain, int n_gyros) {
    auto session = dds::Session::open(domain);
    if (!session) return session.error();
    auto health = session->reader<tetra_Health>(dds::health_qos());
    if (!health) return health.error();
    auto event = session->reader<tetra_FdiEvent>(dds::event_qos());
    if (!event) return event.error();
    return DemoWatch(std::move(session).value(), std::move(health).value(), std::move(event).value(),
                     n_gyros);
  }
  //! Takes the Health and events received.
  void take();
  //! One progress line: the latest Health and attitude error.
  void print_progress(const SimDdsScore& score);
  const Timeline& timeline() const { return timeline_; }

 private:
  DemoWatch(dds::Session session, dds::Reader<tetra_Health> health, dds::Reader<tetra_FdiEvent> event, int n)
      : session_(std::move(session)),
        health_reader_(std::move(health)),
        event_reader_(std::move(event)),
        n_(n) {}
  void on_event(const fdi::FdiEvent& e);

  dds::Session session_;
  dds::Reader<tetra_Health> health_reader_;
  dds::Reader<tetra_FdiEvent> event_reader_;
  int n_;
  Timeline timeline_;
  std::optional<dds::HealthView> health_;
};

void DemoWatch::take() {
  (void)health_reader_.take(
      [&](const tetra_Health& msg, const dds_sample_info_t&) { health_ = dds::from_wire(msg); });
  (void)event_reader_.take(
      [&](const tetra_FdiEvent& msg, const dds_sample_info_t&) { on_event(dds::from_wire(msg).event); });
}

void DemoWatch::on_event(const fdi::FdiEvent& e) {
  const double t = ns_to_seconds(e.stamp_ns);
  std::cout << "  event  " << fdi::to_json(e, n_) << '\n';
  if (e.type == fdi::EventType::kDetected && !timeline_.detected_s) timeline_.detected_s = t;
  if (e.type == fdi::EventType::kIsolated && !timeline_.isolated_s) {
    timeline_.isolated_s = t;
    timeline_.isolated_gyro = e.gyro;
    timeline_.isolated_kind = fdi::to_string(e.kind);
  }
  if (e.type == fdi::EventType::kReconfigured && !timeline_.reconfigured_s) {
    timeline_.reconfigured_s = t;
    timeline_.reconfigured_gyros = mask_to_string(e.gyros, n_);
  }
}

void DemoWatch::print_progress(const SimDdsScore& score) {
  take();
  std::cout << "  t=" << fixed(score.series.empty() ? 0.0 : score.series.back().time_s, 1) << " s";
  if (health_) {
    const auto& h = health_->health;
    std::cout << "  mode " << fdi::to_string(h.mode) << "  gyros " << mask_to_string(h.used, n_) << "  [";
    for (std::size_t i = 0; i < h.gyros.size(); ++i) {
      std::cout << (i ? " " : "") << i + 1 << ":" << fdi::to_string(h.gyros[i].state);
    }
    std::cout << "]  parity " << fixed(h.parity_residual, 2) << " σ  cusum " << fixed(h.cusum, 1) << "/"
              << fixed(h.cusum_threshold, 1);
  }
  if (!score.series.empty())
    std::cout << "  attitude error " << fixed(score.series.back().error_deg * 3600.0, 1) << " arcsec";
  std::cout << '\n' << std::flush;
}

//! What the run showed, for the summary.
struct DemoOutcome {
  const sim::FaultSpec& fault;
  const std::string& fault_text;
  const Timeline& timeline;
  const SimDdsScore& score;
  bool acknowledged = false;
  int fusion_status = -1;
};

void print_summary(const DemoOutcome& r, const DemoOptions& o, const std::string& dir) {
  const double fault_s = r.fault.at_s;
  const Timeline& timeline = r.timeline;
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
  Child monitor(spawn_self({"monitor", "--once", "--unit", unit, "--domain", domain_text, "--timeout", "5"}));
  monitor.wait();
  // The operator's side: reinstate the failed gyro; the service obeys and acknowledges it as an event.
  const std::string gyro_text = std::to_string(gyro);
  std::cout << "\noperator: tetra command --unit " << unit << " reinstate " << gyro_text << '\n'
            << std::flush;
  Child command(spawn_self(
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
  const int pid = spawn_self({"ground", "--listen", o.listen, "--domain", std::to_string(o.domain)},
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
  auto simulator = demo_simulator(o, *fault, first);
  if (!simulator) return report("demo", simulator.error());
  auto dir = demo_folder(o.keep_dir);
  if (!dir) return report("demo", dir.error());
  if (auto s = write_service_files(*dir, *simulator, first, o.rate_hz); !s) return report("demo", s.error());

  print_banner(o, *simulator, *dir);
  Child fusion(spawn_self({"fusion", "--config", *dir + "/fusion.yaml", "--domain", std::to_string(o.domain)},
                          *dir + "/fusion.log", *dir + "/fusion.log"));
  if (fusion.pid() <= 0) return report("demo", failure("cannot start tetra fusion"));
  std::cout << "  service pid " << fusion.pid() << '\n';
  Child ground(start_ground(o, *dir));
  if (o.web && ground.pid() <= 0) return report("demo", failure("cannot start tetra ground"));
  auto watch = DemoWatch::open(o.domain, simulator->gyro_count());
  if (!watch) return report("demo", watch.error());

  SimDdsOptions sim_options;
  sim_options.enabled = true;
  sim_options.domain = o.domain;
  sim_options.speed = o.speed;
  sim_options.wait_readers = 1;  // the service
  auto score = run_sim_dds(*simulator, sim_options, &shutdown,
                           [&](const SimDdsScore& progress) { watch->print_progress(progress); });
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
