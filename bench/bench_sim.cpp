// Simulator costs: one gyro-model sample, one orbit epoch (truth motion + 4 gyros + reference),
// a whole 600 k-epoch run in memory without file output, and the turntable plan.
#include <benchmark/benchmark.h>

#include "tetra/sim/gyro_model.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"
#include "tetra/sim/turntable.hpp"

namespace {

void BM_GyroChannelSample(benchmark::State& state) {
  const tetra::Calibration unit = tetra::seed_as_built_unit();
  tetra::sim::GyroChannel ch(unit.gyros[0], tetra::sim::GyroModelOptions{}, 0.01, 1, 0);
  const Eigen::Vector3d omega_dps(0.01, -0.06, 0.002);
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ch.sample_V(omega_dps, t));
    t += 0.01;
  }
}
BENCHMARK(BM_GyroChannelSample);

tetra::sim::Scenario orbit_100hz() {
  tetra::sim::Scenario sc = tetra::sim::builtin_scenario("orbit").value();
  sc.rate_hz = 100.0;
  sc.reference.rate_hz = 1.0;
  return sc;
}

void BM_OrbitEpoch(benchmark::State& state) {
  auto sim = tetra::sim::Simulator::create(orbit_100hz(), tetra::sim::SimOptions{}).value();
  tetra::sim::SimEpoch epoch;
  for (auto _ : state) {
    if (!sim.next(epoch)) sim.reset();
    benchmark::DoNotOptimize(epoch.raw_V.data());
  }
}
BENCHMARK(BM_OrbitEpoch);

// The performance case without file output: 100 min at 100 Hz, 4 gyros, 1 Hz reference.
void BM_Orbit600kEpochsInMemory(benchmark::State& state) {
  const tetra::sim::Scenario sc = orbit_100hz();
  for (auto _ : state) {
    auto log = tetra::sim::simulate_log(sc, tetra::sim::SimOptions{});
    benchmark::DoNotOptimize(log.value().values.data());
  }
}
BENCHMARK(BM_Orbit600kEpochsInMemory)->Unit(benchmark::kMillisecond);

void BM_TurntablePlan10Hz(benchmark::State& state) {
  const tetra::Calibration unit = tetra::seed_as_built_unit();
  for (auto _ : state) {
    auto log = tetra::sim::simulate_turntable(unit, tetra::sim::TurntablePlan{}, 1);
    benchmark::DoNotOptimize(log.value().g_V.data());
  }
}
BENCHMARK(BM_TurntablePlan10Hz)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
