// Turntable calibration on the large case: 16 sequences × 10 min at 100 Hz (960 000 rows),
// seed unit, 6 deg/s. Measures reading the file, interpreting the encoders and both estimators.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "tetra/core/calibration.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/sim/turntable.hpp"

namespace {

struct Fixture {
  tetra::TurntableLog log;
  tetra::TurntableMotion motion;
  std::string path;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture out;
    tetra::sim::TurntablePlan plan;
    plan.revolutions = 10;  // 10 min per sequence at 6 deg/s
    plan.rate_hz = 100.0;
    auto log = tetra::sim::simulate_turntable(tetra::seed_as_built_unit(), plan, 7);
    if (!log) {
      std::fprintf(stderr, "simulation failed: %s\n", log.error().message.c_str());
      std::exit(1);
    }
    out.log = std::move(log.value());
    out.path = (std::filesystem::temp_directory_path() / "tetra-bench-turntable.csv").string();
    if (!tetra::write_turntable_log(out.path, out.log)) std::exit(1);
    auto motion = tetra::analyze_turntable(out.log, plan.latitude_deg);
    if (!motion) std::exit(1);
    out.motion = std::move(motion.value());
    return out;
  }();
  return f;
}

void BM_ReadTurntableLog(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    auto log = tetra::read_turntable_log(f.path);
    benchmark::DoNotOptimize(log);
  }
  state.counters["rows"] = static_cast<double>(f.log.rows());
}

void BM_AnalyzeTurntable(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    auto motion = tetra::analyze_turntable(f.log, -23.2);
    benchmark::DoNotOptimize(motion);
  }
}

void BM_Calibrate(benchmark::State& state, tetra::CalibrationMethod method) {
  const Fixture& f = fixture();
  tetra::CalibrationOptions options;
  options.method = method;
  for (auto _ : state) {
    auto result = tetra::calibrate(f.log, f.motion, options);
    benchmark::DoNotOptimize(result);
  }
}

void BM_WholeJob(benchmark::State& state, tetra::CalibrationMethod method) {
  const Fixture& f = fixture();
  tetra::CalibrationOptions options;
  options.method = method;
  for (auto _ : state) {
    auto log = tetra::read_turntable_log(f.path);
    auto motion = tetra::analyze_turntable(*log, -23.2);
    auto result = tetra::calibrate(*log, *motion, options);
    benchmark::DoNotOptimize(result);
  }
}

BENCHMARK(BM_ReadTurntableLog)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AnalyzeTurntable)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Calibrate, sixteen, tetra::CalibrationMethod::kSixteen)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Calibrate, batch, tetra::CalibrationMethod::kBatch)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_WholeJob, sixteen, tetra::CalibrationMethod::kSixteen)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_WholeJob, batch, tetra::CalibrationMethod::kBatch)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
