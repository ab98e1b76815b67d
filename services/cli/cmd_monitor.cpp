// tetra monitor — ground monitoring of every unit on the domain (docs/dds.md).
//
// Reads Health and FdiEvent (transient-local: a late monitor still gets the current health and the
// event history) and Attitude. Shows a dashboard refreshed every --period (≤ 0.5 s: ≥ 2 Hz), or with
// --jsonl streams the same as JSON lines; --once prints every unit's current health (and its event
// history) as soon as they have arrived, and exits. A unit whose last Health is older than three of
// the service's Health periods is shown STALE, one whose Health writer lost its liveliness (service
// killed or gone) SERVICE LOST, with the age of its health and attitude (docs/ground.md).

#include <unistd.h>

#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds_tools/monitor.hpp"

namespace tetra::cli {

namespace {

void add_monitor_options(CLI::App& app, dds_tools::MonitorOptions& o) {
  app.add_option("--unit", o.unit_filter, "show only this unit (default: every unit discovered)");
  app.add_flag("--jsonl", o.jsonl, "JSON lines on stdout instead of the dashboard");
  app.add_flag("--once", o.once, "print each unit's current health (and event history) and exit");
  app.add_option("--period", o.period_s, "[s] refresh period (≤ 0.5: at least 2 Hz)")
      ->check(CLI::Range(0.01, 0.5));
  app.add_option("--duration", o.duration_s, "[s] stop after this long (default: until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--timeout", o.timeout_s, "[s] with --once: give up when no unit answers within this")
      ->check(CLI::PositiveNumber);
  add_domain_option(app, o.domain);
}

}  // namespace

int cmd_monitor(int argc, char** argv) {
  dds::ShutdownSignal shutdown;
  CLI::App app{"Ground monitoring: health, attitude and events of every unit on the DDS domain.", "monitor"};
  dds_tools::MonitorOptions o;
  add_monitor_options(app, o);
  if (auto exit = parse(app, argc, argv)) return *exit;
  o.terminal = isatty(STDOUT_FILENO) != 0;
  if (auto monitored = dds_tools::monitor_units(o, shutdown, std::cout); !monitored)
    return report("monitor", monitored.error());
  return kExitOk;
}

}  // namespace tetra::cli
