#include "sim_dds_loop.hpp"

#include <iostream>

#include "cli_common.hpp"
#include "dds_common.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds_tools/sim_dds_estimator.hpp"
#include "tetra/dds_tools/sim_dds_link.hpp"
#include "tetra/sim/closed_loop_run.hpp"

namespace tetra::cli {

using dds_tools::DdsEstimator;
using dds_tools::SimDdsLink;

namespace {

constexpr const char* kDdsLoopName = "sim";

const dds::ShutdownSignal* g_shutdown = nullptr;

bool shutdown_requested() {
  return g_shutdown != nullptr && g_shutdown->requested();
}

}  // namespace

int sim_dds_closed_loop_main(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                             const ClosedLoopCliOptions& loop_options, const SimDdsOptions& dds_options) {
  if (Status st = report::check_closed_loop_options(scenario, loop_options, true); !st)
    return report(kDdsLoopName, st.error());
  auto simulator = sim::ClosedLoopSimulator::create(scenario, sim_options);
  if (!simulator) return report(kDdsLoopName, simulator.error());
  dds::ShutdownSignal shutdown;
  g_shutdown = &shutdown;
  const std::string unit = dds_options.unit.empty() ? scenario.unit.unit : dds_options.unit;
  auto link = SimDdsLink::open(unit, scenario.rate_hz, dds_options, &shutdown);
  if (!link) return report(kDdsLoopName, link.error());
  DdsEstimator estimator(**link, !loop_options.real_time, dds_options.speed);
  auto record = sim::run_closed_loop(*simulator, estimator, shutdown_requested);
  g_shutdown = nullptr;
  if (!record) return report(kDdsLoopName, record.error());
  record->fdi_events = false;  // the service's FdiEvent topic is not read here
  if (estimator.missing() > 0) {
    std::cout << "lockstep: " << estimator.missing() << " epochs without their Attitude within "
              << DdsEstimator::kLockstepTimeout_ns / 1'000'000'000
              << " s (the loop went on with the latest)\n";
  }
  const Status st = report::write_closed_loop_outputs(scenario, *simulator, *record, loop_options, std::cout);
  return st ? kExitOk : report(kDdsLoopName, st.error());
}

}  // namespace tetra::cli
