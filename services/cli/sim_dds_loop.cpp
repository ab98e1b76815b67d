#include "sim_dds_loop.hpp"

#include <iostream>

#include "cli_common.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds_tools/sim_dds_estimator.hpp"
#include "tetra/dds_tools/sim_dds_loop.hpp"

namespace tetra::cli {

namespace {

constexpr const char* kDdsLoopName = "sim";

}  // namespace

int sim_dds_closed_loop_main(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                             const ClosedLoopCliOptions& loop_options, const SimDdsOptions& dds_options) {
  if (Status st = report::check_closed_loop_options(scenario, loop_options, true); !st)
    return report(kDdsLoopName, st.error());
  auto simulator = sim::ClosedLoopSimulator::create(scenario, sim_options);
  if (!simulator) return report(kDdsLoopName, simulator.error());
  dds::ShutdownSignal shutdown;
  auto run = dds_tools::run_closed_loop_dds(*simulator, loop_options.real_time, dds_options, shutdown);
  if (!run) return report(kDdsLoopName, run.error());
  if (run->missing > 0) {
    std::cout << "lockstep: " << run->missing << " epochs without their Attitude within "
              << dds_tools::DdsEstimator::kLockstepTimeout_ns / 1'000'000'000
              << " s (the loop went on with the latest)\n";
  }
  const Status st =
      report::write_closed_loop_outputs(scenario, *simulator, run->record, loop_options, std::cout);
  return st ? kExitOk : report(kDdsLoopName, st.error());
}

}  // namespace tetra::cli
