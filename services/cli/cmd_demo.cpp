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
#include "tetra/dds/entity.hpp"
#include "tetra/dds/loopback_config.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"
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

}  // namespace

int cmd_demo(int argc, char** argv) {
  dds::ShutdownSignal shutdown;
  CLI::App app{
      "Simulator + fusion service + monitor on a private loopback DDS domain, with a gyro failure "
      "injected mid-run, and a summary. Takes about 30 s.",
      "demo"};
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
  app.add_option("--scenario", scenario_name,
                 "simulated motion: static, lab-orbit, orbit, slews or FILE.yaml")
      ->capture_default_str();
  app.add_option("--fault", fault_text, "the injected failure (docs/interfaces.md §2.7)")
      ->capture_default_str();
  app.add_option("--seconds", seconds, "[s] simulated duration")
      ->check(CLI::Range(5.0, 600.0))
      ->capture_default_str();
  app.add_option("--rate-hz", rate_hz, "[Hz] gyro rate")
      ->check(CLI::Range(1.0, 2000.0))
      ->capture_default_str();
  app.add_option("--speed", speed, "times faster than real time")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  app.add_option("--seed", seed, "simulation seed")->capture_default_str();
  app.add_option("--keep", keep_dir, "keep the service's configuration and log in this folder");
  app.add_flag("--web", web, "also run the ground station in the browser (tetra ground) and print its URL");
  app.add_option("--listen", listen, "--web: HOST:PORT of the ground station")->capture_default_str();
  app.add_option("--domain", domain, "DDS domain id (default: 150 + pid % 80, private to this run)")
      ->check(CLI::Range(0, 232));
  if (auto exit = parse(app, argc, argv)) return *exit;

  // Private loopback domain for this process and its children.
  setenv("CYCLONEDDS_URI", dds::kLoopbackConfigXml, 1);

  auto fault = sim::parse_fault_spec(fault_text);
  if (!fault) return report("demo", fault.error());
  auto scenario = std::filesystem::exists(scenario_name) ? sim::read_scenario(scenario_name)
                                                         : sim::builtin_scenario(scenario_name);
  if (!scenario) return report("demo", scenario.error());
  scenario->duration_s = seconds;
  scenario->rate_hz = rate_hz;
  if (fault->at_s >= seconds)
    return report("demo", bad_input("--fault: at=" + fixed(fault->at_s, 1) + " is after the end"));
  sim::SimOptions options;
  options.seed = seed;
  options.faults.push_back(*fault);
  auto simulator = sim::Simulator::create(*scenario, options);
  if (!simulator) return report("demo", simulator.error());
  sim::SimEpoch first;
  if (!simulator->next(first)) return report("demo", bad_input("the scenario has no epochs"));
  simulator->reset();

  // The service's configuration: the simulated unit's as-built calibration, its initial attitude.
  std::string dir = keep_dir;
  if (dir.empty()) {
    char tmpl[] = "/tmp/tetra-demo-XXXXXX";
    if (mkdtemp(tmpl) == nullptr) return report("demo", failure("cannot create a temporary folder"));
    dir = tmpl;
  }
  std::filesystem::create_directories(dir);
  const std::string unit = scenario->unit.unit;
  if (auto s = write_calibration(dir + "/calibration.yaml", scenario->unit); !s)
    return report("demo", s.error());
  {
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
    if (auto s = write_text_file(dir + "/fusion.yaml", config.str()); !s) return report("demo", s.error());
  }

  std::cout << "tetra demo: domain " << domain << " (loopback only), unit " << unit << ", scenario "
            << scenario->name << ", " << fixed(seconds, 0) << " s at " << fixed(rate_hz, 0) << " Hz, "
            << fixed(speed, 1) << "x real time\n"
            << "  fault: " << fault_text << "\n  the service: tetra fusion --config " << dir
            << "/fusion.yaml\n"
            << std::flush;
  const std::string domain_text = std::to_string(domain);
  Child fusion(spawn_self({"fusion", "--config", dir + "/fusion.yaml", "--domain", domain_text},
                          dir + "/fusion.log", dir + "/fusion.log"));
  if (fusion.pid() <= 0) return report("demo", failure("cannot start tetra fusion"));
  std::cout << "  service pid " << fusion.pid() << '\n';
  Child ground(web ? spawn_self({"ground", "--listen", listen, "--domain", domain_text}, dir + "/ground.log",
                                dir + "/ground.log")
                   : -1);
  if (web) {
    if (ground.pid() <= 0) return report("demo", failure("cannot start tetra ground"));
    std::cout << "  ground station: http://" << listen << "/  (open it in a browser; log " << dir
              << "/ground.log)\n"
              << std::flush;
  }

  // The monitor's side, in this process: Health and events.
  auto participant = dds::Participant::create(domain);
  if (!participant) return report("demo", participant.error());
  auto topics = dds::Topics::create(*participant);
  if (!topics) return report("demo", topics.error());
  auto health_reader = dds::Reader<tetra_Health>::create(*participant, topics->health, dds::health_qos());
  if (!health_reader) return report("demo", health_reader.error());
  auto event_reader = dds::Reader<tetra_FdiEvent>::create(*participant, topics->event, dds::event_qos());
  if (!event_reader) return report("demo", event_reader.error());

  Timeline timeline;
  std::optional<dds::HealthView> health;
  const int n = simulator->gyro_count();
  const auto watch = [&]() {
    (void)health_reader->take(
        [&](const tetra_Health& msg, const dds_sample_info_t&) { health = dds::from_wire(msg); });
    (void)event_reader->take([&](const tetra_FdiEvent& msg, const dds_sample_info_t&) {
      const auto view = dds::from_wire(msg);
      const auto& e = view.event;
      const double t = ns_to_seconds(e.stamp_ns);
      std::cout << "  event  " << fdi::to_json(e, n) << '\n';
      if (e.type == fdi::EventType::kDetected && !timeline.detected_s) timeline.detected_s = t;
      if (e.type == fdi::EventType::kIsolated && !timeline.isolated_s) {
        timeline.isolated_s = t;
        timeline.isolated_gyro = e.gyro;
        timeline.isolated_kind = fdi::to_string(e.kind);
      }
      if (e.type == fdi::EventType::kReconfigured && !timeline.reconfigured_s) {
        timeline.reconfigured_s = t;
        timeline.reconfigured_gyros = mask_to_string(e.gyros, n);
      }
    });
  };
  const auto progress = [&](const SimDdsScore& score) {
    watch();
    std::cout << "  t=" << fixed(score.series.empty() ? 0.0 : score.series.back().time_s, 1) << " s";
    if (health) {
      const auto& h = health->health;
      std::cout << "  mode " << fdi::to_string(h.mode) << "  gyros " << mask_to_string(h.used, n) << "  [";
      for (std::size_t i = 0; i < h.gyros.size(); ++i) {
        std::cout << (i ? " " : "") << i + 1 << ":" << fdi::to_string(h.gyros[i].state);
      }
      std::cout << "]  parity " << fixed(h.parity_residual, 2) << " σ  cusum " << fixed(h.cusum, 1) << "/"
                << fixed(h.cusum_threshold, 1);
    }
    if (!score.series.empty())
      std::cout << "  attitude error " << fixed(score.series.back().error_deg * 3600.0, 1) << " arcsec";
    std::cout << '\n' << std::flush;
  };

  SimDdsOptions sim_options;
  sim_options.enabled = true;
  sim_options.domain = domain;
  sim_options.speed = speed;
  sim_options.wait_readers = 1;  // the service
  auto score = run_sim_dds(*simulator, sim_options, &shutdown, progress);
  if (!score) {
    fusion.stop();
    return report("demo", failure(score.error().message + " (service log: " + dir + "/fusion.log)"));
  }
  watch();

  std::cout
      << "\nmonitor view after the run (tetra monitor --once; the simulator has stopped, so its gyros are "
         "absent and the unit LOST; the event history is the late joiner's):\n"
      << std::flush;
  Child monitor(spawn_self({"monitor", "--once", "--unit", unit, "--domain", domain_text, "--timeout", "5"}));
  monitor.wait();

  // The operator's side: reinstate the failed gyro; the service obeys and acknowledges it as an event.
  const std::string gyro_text = std::to_string(fault->gyro);
  std::cout << "\noperator: tetra command --unit " << unit << " reinstate " << gyro_text << '\n'
            << std::flush;
  Child command(spawn_self(
      {"command", "--unit", unit, "reinstate", gyro_text, "--domain", domain_text, "--timeout", "5"}));
  const bool acknowledged = command.wait() == 0;
  const int fusion_status = fusion.stop();

  // Summary.
  const double fault_s = fault->at_s;
  double before_deg = 0.0;
  double after_deg = 0.0;
  std::vector<std::pair<double, std::string>> modes;  // (time, "MODE gyros") at each change
  for (const auto& e : score->series) {
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
            << "  fault injected:    " << fault_text << '\n'
            << "  detected:          " << since_fault(timeline.detected_s) << '\n'
            << "  isolated:          " << since_fault(timeline.isolated_s);
  if (timeline.isolated_gyro)
    std::cout << ": gyro " << *timeline.isolated_gyro << " (" << timeline.isolated_kind << ")";
  std::cout << "\n  reconfigured:      " << since_fault(timeline.reconfigured_s);
  if (timeline.reconfigured_s) std::cout << " to gyros " << timeline.reconfigured_gyros;
  std::cout << "\n  mode changes:     ";
  for (const auto& [t, mode] : modes) std::cout << " " << mode << " @" << fixed(t, 2) << "s";
  std::cout << "\n  attitude epochs:   " << score->attitudes_scored << " received of "
            << score->epochs_published << " published\n"
            << "  attitude error:    worst before the fault " << fixed(before_deg * 3600.0, 1) << " arcsec; ";
  if (timeline.reconfigured_s) {
    std::cout << "worst after reconfiguration " << fixed(after_deg * 3600.0, 1) << " arcsec; ";
  }
  std::cout << "at the end "
            << fixed(score->series.empty() ? 0.0 : score->series.back().error_deg * 3600.0, 1) << " arcsec\n"
            << "  operator command:  reinstate " << gyro_text
            << (acknowledged ? ", acknowledged" : ", NOT acknowledged") << '\n'
            << "  service:           exit status " << fusion_status << " after SIGTERM"
            << (keep_dir.empty() ? std::string(" (its log: --keep DIR)") : " (log " + dir + "/fusion.log)")
            << '\n';
  if (web && !shutdown.requested()) {
    std::cout << "\nthe ground station stays up at http://" << listen
              << "/ (the service has stopped: it shows SERVICE LOST); Ctrl-C to end\n"
              << std::flush;
    while (!shutdown.requested()) usleep(100'000);  // no DDS entity left to wait on
  }
  ground.stop();
  if (keep_dir.empty()) std::filesystem::remove_all(dir);
  const bool ok = timeline.isolated_s && score->attitudes_scored > 0;
  return ok || shutdown.requested() ? kExitOk : kExitFailure;
}

}  // namespace tetra::cli
