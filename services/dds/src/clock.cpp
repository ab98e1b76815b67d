#include "tetra/dds/clock.hpp"

#include <dds/dds.h>

#include <ctime>

namespace tetra::dds {

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::int64_t wall_ns() {
  return dds_time();
}

}  // namespace tetra::dds
