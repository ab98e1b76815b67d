// step() allocates nothing in steady state: the global allocator is counted around 20 000 steps that include
// missing samples, invalid samples, one-epoch spikes and reference epochs (all after a warm-up that has seen
// each of them once).
#include <atomic>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

#include "synth.hpp"
#include "tetra/fdi/pipeline.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace tetra::fdi {
namespace {

TEST(PipelineAllocation, SteadyStateStepDoesNotAllocate) {
  const auto cal = seed_as_built_unit();
  auto p = Pipeline::create(cal, PipelineConfig{});
  ASSERT_TRUE(p.ok());
  test::SynthOptions opt;
  opt.reference_period_s = 1.0;
  test::Synth s(cal, opt);
  const auto missing = [](int k) { return k % 37 == 5 || k % 53 == 7; };
  auto perturb = [&missing](Epoch e, int k) {
    if (k % 37 == 5) e.present[static_cast<std::size_t>(k % 4)] = 0;
    if (k % 53 == 7) e.raw[static_cast<std::size_t>((k + 1) % 4)] = std::numeric_limits<double>::quiet_NaN();
    // A one-epoch spike about every 50 s, each gyro in turn (one per spike window), on a step with every
    // sample there: the jump test leaves it out and the three left have no parity, so sigma carries their
    // unchecked rate (Pipeline's cover_unchecked_rate).
    if (k % 500 == 250 && !missing(k) && !missing(k - 1) && !missing(k - 2) && !missing(k - 3))
      e.raw[static_cast<std::size_t>((k / 500) % 4)] += 0.05;
    return e;
  };
  std::vector<Epoch> epochs;
  epochs.reserve(22000);
  for (int k = 0; k < 22000; ++k) epochs.push_back(perturb(s.next(), k));
  for (int k = 0; k < 2000; ++k) (void)p->step(epochs[static_cast<std::size_t>(k)]);
  const long before = g_allocations.load();
  std::size_t events = 0;
  for (int k = 2000; k < 22000; ++k) events += p->step(epochs[static_cast<std::size_t>(k)]).events.size();
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(events, 0U);  // steady state: no fault, no event
}

}  // namespace
}  // namespace tetra::fdi
