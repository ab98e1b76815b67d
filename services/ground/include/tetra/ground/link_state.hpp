#pragma once
// Is what the ground shows of a unit current? LIVE while its Health arrives; STALE when the last
// Health is older than kStalePeriods of the service's own Health period; SERVICE LOST when the
// service's Health writer lost its liveliness (DDS: no live writer left for the unit's instance).

#include <cstdint>
#include <optional>

namespace tetra::ground {

enum class Link : std::uint8_t { kWaiting, kLive, kStale, kServiceLost };
//! "WAITING", "LIVE", "STALE", "SERVICE LOST".
const char* to_string(Link link);

//! Health older than this many of the service's Health periods is stale.
inline constexpr double kStalePeriods = 3.0;
//! [s] the Health period assumed when the service does not state one.
inline constexpr double kDefaultHealthPeriod_s = 0.5;

//! The link state from the age of the last Health (nullopt: none yet), the Health period the service
//! states, and whether its Health writer is alive.
Link link_state(std::optional<std::int64_t> health_age_ns, double health_period_s, bool writer_alive);

}  // namespace tetra::ground
