#pragma once
// The clocks of the benchmark programs: now (monotonic, or a thread's CPU time), and sleeping until an
// absolute time.

#include <time.h>

#include <cstdint>

namespace tetra::bench {

//! [ns] the clock `clock` (CLOCK_MONOTONIC unless told).
inline std::int64_t now_ns(clockid_t clock = CLOCK_MONOTONIC) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

//! Sleeps until CLOCK_MONOTONIC reaches `t_ns`.
inline void sleep_until_ns(std::int64_t t_ns) {
  timespec ts{static_cast<time_t>(t_ns / 1'000'000'000), static_cast<long>(t_ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

}  // namespace tetra::bench
