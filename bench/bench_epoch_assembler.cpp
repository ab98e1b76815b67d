// In-process cost of epoch assembly (services/fusion): four samples in, one epoch out.
#include <benchmark/benchmark.h>

#include "tetra/service/epoch_assembler.hpp"

namespace {

void BM_AssembleEpoch(benchmark::State& state) {
  tetra::service::AssemblerConfig config;  // 4 gyros, 100 Hz
  auto assembler = tetra::service::EpochAssembler::create(config);
  std::vector<tetra::fdi::Epoch> out;
  std::uint64_t k = 0;
  for (auto _ : state) {
    ++k;
    const auto stamp = static_cast<std::int64_t>(k) * config.nominal_period_ns;
    for (int g = 1; g <= 4; ++g) assembler->add_sample(g, k, stamp, 0.1 * g, 0);
    out.clear();
    assembler->poll(0, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(k));
}
BENCHMARK(BM_AssembleEpoch);

}  // namespace

BENCHMARK_MAIN();
