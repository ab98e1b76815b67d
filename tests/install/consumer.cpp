// Uses the installed libraries the way a user's flight software would: a simulated unit (tetra::sim)
// through the fusion and fault-detection pipeline (tetra::fdi), with its calibration (tetra::core).
// Prints one line and exits 0 when the pipeline accepted every epoch of a minute at rest.
#include <cstdio>

#include "tetra/core/calibration_file.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

int main() {
  auto scenario = tetra::sim::builtin_scenario("static");
  if (!scenario) return 1;
  scenario->duration_s = 60.0;
  auto simulator = tetra::sim::Simulator::create(*scenario, tetra::sim::SimOptions{});
  auto pipeline = tetra::fdi::Pipeline::create(scenario->unit, tetra::fdi::PipelineConfig{});
  if (!simulator || !pipeline) return 1;
  int epochs = 0, accepted = 0;
  tetra::sim::SimEpoch sample;
  tetra::fdi::Epoch epoch;
  while (simulator->next(sample)) {
    epoch.stamp_ns = sample.stamp_ns;
    epoch.raw = sample.raw_V;
    epoch.present = sample.present;
    ++epochs;
    if (pipeline->step(epoch).accepted) ++accepted;
  }
  std::printf("tetra consumer: %d of %d epochs accepted, mode %s\n", accepted, epochs,
              tetra::fdi::to_string(pipeline->health().mode));
  return epochs > 0 && accepted == epochs ? 0 : 1;
}
