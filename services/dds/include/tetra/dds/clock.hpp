#pragma once
// The clocks of the DDS services and tools: local monotonic time for latency limits, periods and
// deadlines (never on the wire), and the wall clock DDS stamps samples with.

#include <cstdint>

namespace tetra::dds {

//! [ns] local monotonic clock (for latency limits and periods; never on the wire).
std::int64_t monotonic_ns();

//! [ns] wall clock as DDS stamps it (source timestamps).
std::int64_t wall_ns();

}  // namespace tetra::dds
