// The closed loop over DDS (tetra/dds_tools/sim_dds_loop.hpp).
#include "tetra/dds_tools/sim_dds_loop.hpp"

#include "tetra/dds_tools/sim_dds_estimator.hpp"
#include "tetra/dds_tools/sim_dds_link.hpp"

namespace tetra::dds_tools {

namespace {

const dds::ShutdownSignal* g_loop_shutdown = nullptr;

bool loop_shutdown_requested() {
  return g_loop_shutdown != nullptr && g_loop_shutdown->requested();
}

}  // namespace

Result<DdsClosedLoopRun> run_closed_loop_dds(sim::ClosedLoopSimulator& simulator, bool real_time,
                                             const SimDdsOptions& options,
                                             const dds::ShutdownSignal& shutdown) {
  const sim::Scenario& scenario = simulator.scenario();
  g_loop_shutdown = &shutdown;
  const std::string unit = options.unit.empty() ? scenario.unit.unit : options.unit;
  auto link = SimDdsLink::open(unit, scenario.rate_hz, options, &shutdown);
  if (!link) {
    g_loop_shutdown = nullptr;
    return link.error();
  }
  DdsEstimator estimator(**link, !real_time, options.speed);
  auto record = sim::run_closed_loop(simulator, estimator, loop_shutdown_requested);
  g_loop_shutdown = nullptr;
  if (!record) return record.error();
  record->fdi_events = false;  // the service's FdiEvent topic is not read here
  return DdsClosedLoopRun{std::move(record).value(), estimator.missing()};
}

}  // namespace tetra::dds_tools
