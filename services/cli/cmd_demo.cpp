// tetra demo — simulator + fusion service + monitor on a private loopback DDS domain, a gyro failure
// injected mid-run, and a summary (docs/dds.md). The options; the run: tetra/dds_tools/demo_run.hpp.

#include <unistd.h>

#include <iostream>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds_tools/demo.hpp"
#include "tetra/dds_tools/demo_run.hpp"
#include "tetra/sim/fault.hpp"

namespace tetra::cli {

namespace {

using dds_tools::DemoOptions;

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

}  // namespace

int cmd_demo(int argc, char** argv) {
  dds::ShutdownSignal shutdown;
  CLI::App app{
      "Simulator + fusion service + monitor on a private loopback DDS domain, with a gyro failure "
      "injected mid-run, and a summary. Takes about 5 s (--seconds / --speed; --speed 1 to watch it live).",
      "demo"};
  DemoOptions o;
  o.domain = static_cast<dds_domainid_t>(150 + getpid() % 80);  // private to this run
  add_demo_options(app, o);
  if (auto exit = parse(app, argc, argv)) return *exit;

  auto fault = sim::parse_fault_spec(o.fault_text);
  if (!fault) return report("demo", fault.error());
  auto ok = dds_tools::run_demo(o, *fault, shutdown, std::cout);
  if (!ok) return report("demo", ok.error(), {{dds_tools::kSubjectFault, "--fault: {message}"}});
  return *ok ? kExitOk : kExitFailure;
}

}  // namespace tetra::cli
