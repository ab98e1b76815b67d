// Allan analysis costs on the benchmark's scale: 2 h at 100 Hz = 720 000 samples per gyro.
//  - overlapping ADEV at the default τ set (≈ 10 per decade): O(n) per τ
//  - the whole analysis of one series (ADEV, EDF/χ² intervals, NNLS fit, three reweighting passes)
//  - the same with 5 % of the samples missing (the gap-aware loop)
//  - parsing the gyro log text (4 gyros)
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tetra/core/allan.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"

namespace {

constexpr std::size_t kSamples = 720000;
constexpr double kTau0 = 0.01;

std::vector<double> white(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 3e-4);
  std::vector<double> y(n);
  for (double& v : y) v = 4e-3 + g(rng);
  return y;
}

void BM_OverlappingAdevDefaultTaus(benchmark::State& state) {
  const auto y = white(kSamples, 1);
  const auto ms = *tetra::allan::averaging_factors({}, y.size(), kTau0);
  for (auto _ : state) benchmark::DoNotOptimize(tetra::allan::overlapping_avar(y, {}, kTau0, ms));
  state.counters["taus"] = static_cast<double>(ms.size());
}
BENCHMARK(BM_OverlappingAdevDefaultTaus)->Unit(benchmark::kMillisecond);

void BM_AnalyzeSeries(benchmark::State& state) {
  const auto y = white(kSamples, 2);
  for (auto _ : state) benchmark::DoNotOptimize(tetra::allan::analyze_series(y, {}, kTau0, {}));
}
BENCHMARK(BM_AnalyzeSeries)->Unit(benchmark::kMillisecond);

void BM_AnalyzeSeriesWithGaps(benchmark::State& state) {
  const auto y = white(kSamples, 3);
  std::vector<std::uint8_t> present(y.size(), 1);
  std::mt19937_64 rng(4);
  for (std::size_t k = 0; k < y.size() / 20 / 25; ++k) {
    const std::size_t start = rng() % (y.size() - 50);
    for (std::size_t i = start; i < start + 25; ++i) present[i] = 0;
  }
  for (auto _ : state) benchmark::DoNotOptimize(tetra::allan::analyze_series(y, present, kTau0, {}));
}
BENCHMARK(BM_AnalyzeSeriesWithGaps)->Unit(benchmark::kMillisecond);

void BM_ParseGyroLog(benchmark::State& state) {
  const std::size_t rows = 100000;
  std::string text = "# units=dps\ntime_s,g1,g2,g3,g4\n";
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 3e-4);
  char buf[32];
  for (std::size_t i = 0; i < rows; ++i) {
    std::snprintf(buf, sizeof buf, "%.3f", static_cast<double>(i) * kTau0);
    text += buf;
    for (int k = 0; k < 4; ++k) {
      std::snprintf(buf, sizeof buf, ",%.8g", 4e-4 + g(rng));
      text += buf;
    }
    text += '\n';
  }
  for (auto _ : state) benchmark::DoNotOptimize(tetra::parse_gyro_log(text, "bench.csv"));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(text.size()));
  state.counters["rows"] = static_cast<double>(rows);
}
BENCHMARK(BM_ParseGyroLog)->Unit(benchmark::kMillisecond);

}  // namespace
BENCHMARK_MAIN();
