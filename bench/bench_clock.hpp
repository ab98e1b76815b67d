#pragma once
// The monotonic clock of the DDS benchmark programs: now, and sleeping until an absolute time.

#include <time.h>

#include <cstdint>

namespace tetra::bench {

//! [ns] CLOCK_MONOTONIC.
inline std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

//! Sleeps until CLOCK_MONOTONIC reaches `t_ns`.
inline void sleep_until_ns(std::int64_t t_ns) {
  timespec ts{static_cast<time_t>(t_ns / 1'000'000'000), static_cast<long>(t_ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

}  // namespace tetra::bench
