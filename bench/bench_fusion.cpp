// Cost of one pipeline step with 4 gyros and every detector (χ², CUSUM, jump test, signatures, reference).
// Also writes the synthetic 10 Hz log used by bench/replay.sh: `bench_fusion --write-log PATH SECONDS`.
// `bench_fusion --steps N REFERENCE` runs exactly N steps (REFERENCE 0 or 1) outside the benchmark loop: a
// fixed workload for an instruction count that does not depend on the machine's load, e.g.
//   valgrind --tool=callgrind --toggle-collect='tetra::fdi::Pipeline::step(*' bench_fusion --steps 60000 1
#include <cstdlib>
#include <cstring>
#include <iostream>

#include <benchmark/benchmark.h>

#include "../tests/fusion/synth.hpp"
#include "bench_clock.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/fdi/pipeline.hpp"

namespace {

std::vector<tetra::fdi::Epoch> make_epochs(std::size_t n, double reference_period_s) {
  tetra::test::SynthOptions opt;
  opt.reference_period_s = reference_period_s;
  tetra::test::Synth s(tetra::seed_as_built_unit(), opt);
  std::vector<tetra::fdi::Epoch> epochs;
  epochs.reserve(n);
  for (std::size_t k = 0; k < n; ++k) epochs.push_back(s.next());
  return epochs;
}

// Steady state over a 100-min orbit at 10 Hz; the reference (1 Hz) brings in the reference test.
void BM_PipelineStep(benchmark::State& state) {
  const auto epochs = make_epochs(60000, state.range(0) != 0 ? 1.0 : 0.0);
  auto p = tetra::fdi::Pipeline::create(tetra::seed_as_built_unit(), tetra::fdi::PipelineConfig{});
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == epochs.size()) {
      state.PauseTiming();
      p->reset();
      k = 0;
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(p->step(epochs[k++]));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PipelineStep)->Arg(0)->Arg(1)->ArgName("reference");

// A persistent unisolated fault (ramp): every epoch also runs the onset test and the sigma inflation.
void BM_PipelineStepSuspect(benchmark::State& state) {
  tetra::test::SynthOptions opt;
  tetra::test::Synth s(tetra::seed_as_built_unit(), opt,
                       tetra::test::SynthFault{1, tetra::fdi::FaultKind::kRamp, false, 10.0, 1e-5});
  std::vector<tetra::fdi::Epoch> epochs;
  epochs.reserve(60000);
  for (int k = 0; k < 60000; ++k) epochs.push_back(s.next());
  auto p = tetra::fdi::Pipeline::create(tetra::seed_as_built_unit(), tetra::fdi::PipelineConfig{});
  auto warm_up = [&] {
    p->reset();
    for (std::size_t k = 0; k < 1000; ++k)
      (void)p->step(epochs[k]);  // into SUSPECT (detected ≈ 20 s after 10 s)
  };
  warm_up();
  std::size_t k = 1000;
  for (auto _ : state) {
    if (k == epochs.size()) {
      state.PauseTiming();
      warm_up();
      k = 1000;
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(p->step(epochs[k++]));
  }
  state.counters["suspect"] = p->health().mode == tetra::fdi::Mode::kSuspect ? 1.0 : 0.0;
}
BENCHMARK(BM_PipelineStepSuspect);

int run_steps(long n, bool reference) {
  const auto epochs = make_epochs(static_cast<std::size_t>(n), reference ? 1.0 : 0.0);
  auto p = tetra::fdi::Pipeline::create(tetra::seed_as_built_unit(), tetra::fdi::PipelineConfig{});
  std::size_t events = 0;
  // The thread's CPU time (not the wall clock): time spent descheduled by other processes is left out.
  const std::int64_t t0_ns = tetra::bench::now_ns(CLOCK_THREAD_CPUTIME_ID);
  for (const auto& e : epochs) events += p->step(e).events.size();
  const std::int64_t cpu_ns = tetra::bench::now_ns(CLOCK_THREAD_CPUTIME_ID) - t0_ns;
  std::cout << epochs.size() << " steps, " << events << " events, "
            << static_cast<double>(cpu_ns) / static_cast<double>(epochs.size()) << " ns CPU a step\n";
  return 0;
}

int write_log(const char* path, double seconds) {
  tetra::test::SynthOptions opt;
  tetra::test::Synth s(tetra::seed_as_built_unit(), opt);
  tetra::GyroLogWriter w;
  if (!w.open(path, 4, false, false).ok()) return 1;
  const auto n = static_cast<int>(seconds / opt.period_s);
  for (int k = 0; k < n; ++k) {
    const auto& e = s.next();
    if (!w.write(tetra::ns_to_seconds(e.stamp_ns), e.raw, e.present).ok()) return 1;
  }
  return w.close().ok() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::strcmp(argv[1], "--write-log") == 0) return write_log(argv[2], std::atof(argv[3]));
  if (argc == 4 && std::strcmp(argv[1], "--steps") == 0)
    return run_steps(std::atol(argv[2]), std::atoi(argv[3]) != 0);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
