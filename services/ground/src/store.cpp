#include "tetra/ground/store.hpp"

#include <algorithm>
#include <cmath>

#include "tetra/core/units.hpp"
#include "tetra/ground/encode.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {

using nlohmann::json;

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

GroundStore::GroundStore(StoreConfig config)
    : config_(config),
      attitude_period_ns_(seconds_to_ns(1.0 / config.attitude_rate_hz)),
      stream_(config.stream_capacity) {}

GroundStore::Unit* GroundStore::unit(const std::string& name) {
  auto it = units_.find(name);
  if (it != units_.end()) return &it->second;
  if (units_.size() >= config_.max_units) return nullptr;
  const auto items = [&](double rate_hz) {
    return static_cast<std::size_t>(std::ceil(config_.history_s * rate_hz));
  };
  return &units_
              .try_emplace(name, items(config_.health_rate_hz), items(config_.attitude_rate_hz),
                           config_.events_per_unit)
              .first->second;
}

int GroundStore::gyro_count(const Unit& u) const {
  return u.health.empty() ? 4 : static_cast<int>(u.health.newest().value.health.gyros.size());
}

void GroundStore::stream(const char* event, const json& data) {
  stream_.push({next_id_++, event, json_text(data)});
  arrived_.notify_all();
  if (listener_) listener_();
}

void GroundStore::set_listener(std::function<void()> listener) {
  const std::lock_guard lock(mutex_);
  listener_ = std::move(listener);
}

void GroundStore::add_health(const dds::HealthView& health, std::int64_t utc_ns, std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  Unit* u = unit(health.unit);
  if (u == nullptr) return;
  u->health.push({utc_ns, health});
  u->health_received_ns = now_ns;
  u->writer_alive = true;
  stream("health", health_json(health, utc_ns));
}

void GroundStore::add_attitude(const std::string& name, const fdi::AttitudeEstimate& attitude,
                               std::int64_t utc_ns, std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  Unit* u = unit(name);
  if (u == nullptr) return;
  u->attitude_received_ns = now_ns;
  // Keep one per attitude period of sensor time (a sensor restart, time going back, keeps at once).
  // Half a sample of slack: 100 Hz stamps with jitter still give exactly 10 Hz.
  const std::int64_t slack_ns = attitude_period_ns_ / 20;
  if (u->last_kept_stamp_ns && attitude.stamp_ns > *u->last_kept_stamp_ns &&
      attitude.stamp_ns - *u->last_kept_stamp_ns < attitude_period_ns_ - slack_ns) {
    return;
  }
  u->last_kept_stamp_ns = attitude.stamp_ns;
  u->attitude.push({utc_ns, attitude});
  stream("attitude", attitude_json(name, attitude, utc_ns));
}

void GroundStore::add_event(const dds::EventView& event, std::int64_t utc_ns) {
  const std::lock_guard lock(mutex_);
  Unit* u = unit(event.unit);
  if (u == nullptr) return;
  u->events.push({utc_ns, event});
  stream("event", event_json(event, gyro_count(*u), utc_ns));
}

void GroundStore::set_writer_alive(const std::string& name, bool alive, std::int64_t now_ns) {
  {
    const std::lock_guard lock(mutex_);
    Unit* u = unit(name);
    if (u == nullptr || u->writer_alive == alive) return;
    u->writer_alive = alive;
  }
  update_links(now_ns);
}

json GroundStore::link_json(const std::string& name, const Unit& u, std::int64_t now_ns) const {
  const auto age = [&](const std::optional<std::int64_t>& received) {
    return received ? json(ns_to_seconds(now_ns - *received)) : json(nullptr);
  };
  const double period_s = u.health.empty() ? 0.0 : u.health.newest().value.health_period_s;
  return {{"type", "link"},
          {"unit", name},
          {"unit_id", unit_id(name)},
          {"state", to_string(u.link)},
          {"health_age_s", age(u.health_received_ns)},
          {"attitude_age_s", age(u.attitude_received_ns)},
          {"health_period_s", period_s},
          {"stale_after_s", kStalePeriods * (period_s > 0 ? period_s : kDefaultHealthPeriod_s)}};
}

void GroundStore::update_links(std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  const std::int64_t period_ns = seconds_to_ns(config_.link_period_s);
  for (auto& [name, u] : units_) {
    const std::optional<std::int64_t> age =
        u.health_received_ns ? std::optional(now_ns - *u.health_received_ns) : std::nullopt;
    const double period_s = u.health.empty() ? 0.0 : u.health.newest().value.health_period_s;
    const Link link = link_state(age, period_s, u.writer_alive);
    if (link == u.link && now_ns - u.link_streamed_ns < period_ns) continue;
    u.link = link;
    u.link_streamed_ns = now_ns;
    stream("link", link_json(name, u, now_ns));
  }
}

StreamRead GroundStore::read_stream(std::uint64_t after, std::size_t max,
                                    std::chrono::milliseconds wait) const {
  std::unique_lock lock(mutex_);
  arrived_.wait_for(lock, wait, [&] { return next_id_ - 1 > after; });
  StreamRead read;
  if (stream_.empty()) return read;
  const std::uint64_t first = stream_[0].id;
  if (after + 1 < first) {
    read.gap = after != 0;
    after = first - 1;
  }
  for (std::size_t i = static_cast<std::size_t>(after + 1 - first);
       i < stream_.size() && read.messages.size() < max; ++i) {
    read.messages.push_back(stream_[i]);
  }
  return read;
}

std::uint64_t GroundStore::last_id() const {
  const std::lock_guard lock(mutex_);
  return next_id_ - 1;
}

std::size_t GroundStore::stream_dropped() const {
  const std::lock_guard lock(mutex_);
  return stream_.dropped();
}

std::vector<StreamMessage> GroundStore::snapshot(std::int64_t now_ns) const {
  const std::lock_guard lock(mutex_);
  std::vector<StreamMessage> out;
  for (const auto& [name, u] : units_) {
    if (!u.health.empty()) {
      const auto& h = u.health.newest();
      out.push_back({0, "health", json_text(health_json(h.value, h.utc_ns))});
    }
    if (!u.attitude.empty()) {
      const auto& a = u.attitude.newest();
      out.push_back({0, "attitude", json_text(attitude_json(name, a.value, a.utc_ns))});
    }
    out.push_back({0, "link", json_text(link_json(name, u, now_ns))});
  }
  return out;
}

json GroundStore::units_json(std::int64_t now_ns) const {
  const std::lock_guard lock(mutex_);
  json out = json::array();
  for (const auto& [name, u] : units_) {
    json entry = link_json(name, u, now_ns);
    entry["gyro_count"] = gyro_count(u);
    out.push_back(std::move(entry));
  }
  return out;
}

Result<json> GroundStore::history(const std::string& name, const std::string& kind, double start_ms,
                                  double end_ms, std::size_t max_points) const {
  const std::lock_guard lock(mutex_);
  const auto it = units_.find(name);
  if (it == units_.end()) return bad_input("unit '" + name + "' unknown to this ground station");
  const Unit& u = it->second;
  const int n = gyro_count(u);
  json out = json::array();
  const auto collect = [&](const auto& ring, auto encode) {
    const auto before = [](double ms) { return [ms](const auto& item) { return utc_ms(item.utc_ns) < ms; }; };
    const std::size_t first = ring.partition_point(before(start_ms));
    const std::size_t last =
        ring.partition_point([end_ms](const auto& item) { return utc_ms(item.utc_ns) <= end_ms; });
    if (last <= first) return;
    const std::size_t count = last - first;
    const std::size_t stride = max_points == 0 ? 1 : std::max<std::size_t>(1, (count - 1) / max_points + 1);
    for (std::size_t i = first; i < last; i += stride) out.push_back(encode(ring[i]));
  };
  if (kind == "health") {
    collect(u.health, [](const auto& h) { return health_json(h.value, h.utc_ns); });
  } else if (kind == "attitude") {
    collect(u.attitude, [&](const auto& a) { return attitude_json(name, a.value, a.utc_ns); });
  } else if (kind == "event") {
    collect(u.events, [&](const auto& e) { return event_json(e.value, n, e.utc_ns); });
  } else {
    return bad_input("history kind '" + kind + "': expected health, attitude or event");
  }
  return out;
}

}  // namespace tetra::ground
