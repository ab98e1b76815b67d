#include "tetra/ground/link_state.hpp"

#include "tetra/core/units.hpp"

namespace tetra::ground {

const char* to_string(Link link) {
  switch (link) {
    case Link::kLive:
      return "LIVE";
    case Link::kStale:
      return "STALE";
    case Link::kServiceLost:
      return "SERVICE LOST";
    default:
      return "WAITING";
  }
}

Link link_state(std::optional<std::int64_t> health_age_ns, double health_period_s, bool writer_alive) {
  if (!health_age_ns) return Link::kWaiting;
  if (!writer_alive) return Link::kServiceLost;
  const double period_s = health_period_s > 0.0 ? health_period_s : kDefaultHealthPeriod_s;
  const double age_s = ns_to_seconds(*health_age_ns);
  return age_s > kStalePeriods * period_s ? Link::kStale : Link::kLive;
}

}  // namespace tetra::ground
