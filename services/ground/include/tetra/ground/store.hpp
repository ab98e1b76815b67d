#pragma once
// What the ground station knows, shared by the DDS thread that fills it and the HTTP threads that
// read it: per unit, a bounded history (Health, Attitude decimated to a fixed rate, FdiEvents) and its
// link state; and one stream of numbered messages every browser follows (server-sent events), kept
// in a ring so a browser that reconnects resumes after the last message it saw (Last-Event-ID).
// Memory is bounded: every buffer has a fixed capacity and at most `max_units` units are kept.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tetra/core/result.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/ground/link_state.hpp"
#include "tetra/ground/ring_buffer.hpp"

namespace tetra::ground {

//! [ns] the local monotonic clock (CLOCK_MONOTONIC) the store's `now_ns` arguments are read from.
std::int64_t steady_now_ns();

struct StoreConfig {
  double history_s = 3600.0;       //!< [s] history kept per unit (Health, Attitude)
  double attitude_rate_hz = 10.0;  //!< [Hz] Attitude kept and streamed (decimated from the service's)
  double health_rate_hz = 4.0;     //!< [Hz] Health rate the history is sized for (periodic + changes)
  std::size_t events_per_unit = 4096;
  std::size_t stream_capacity = 16384;  //!< messages a reconnecting browser can catch up on
  std::size_t max_units = 64;
  double link_period_s = 1.0;  //!< [s] a "link" message per unit at least this often (ages)
};

//! One message of the stream: SSE `id`, `event` and `data` (JSON text).
struct StreamMessage {
  std::uint64_t id = 0;
  std::string event;
  std::string data;
};

struct StreamRead {
  std::vector<StreamMessage> messages;
  bool gap = false;  //!< messages after the requested id were already dropped: reload history
};

class GroundStore {
 public:
  explicit GroundStore(StoreConfig config);

  //! `utc_ns`: DDS source timestamp; `now_ns`: local monotonic time of reception.
  void add_health(const dds::HealthView& health, std::int64_t utc_ns, std::int64_t now_ns);
  //! Kept (and streamed) when at least 1/attitude_rate_hz of sensor time after the last one kept.
  void add_attitude(const std::string& unit, const fdi::AttitudeEstimate& attitude, std::int64_t utc_ns,
                    std::int64_t now_ns);
  void add_event(const dds::EventView& event, std::int64_t utc_ns);
  //! The unit's Health writer gained or lost its liveliness.
  void set_writer_alive(const std::string& unit, bool alive, std::int64_t now_ns);
  //! Recomputes link states; streams a "link" message on every change and every link_period_s.
  void update_links(std::int64_t now_ns);

  //! Messages with id > `after` (at most `max`), waiting up to `wait` for one.
  StreamRead read_stream(std::uint64_t after, std::size_t max, std::chrono::milliseconds wait) const;
  std::uint64_t last_id() const;
  //! The latest health, attitude and link of every unit, as stream messages without ids.
  std::vector<StreamMessage> snapshot(std::int64_t now_ns) const;
  //! Units and their link states.
  nlohmann::json units_json(std::int64_t now_ns) const;
  //! History of one unit: `kind` "health", "attitude" or "event", UTC in [start_ms, end_ms], evenly
  //! thinned to at most `max_points`.
  Result<nlohmann::json> history(const std::string& unit, const std::string& kind, double start_ms,
                                 double end_ms, std::size_t max_points) const;
  //! Messages dropped from the stream ring, items dropped from the histories (bounded memory).
  std::size_t stream_dropped() const;
  //! Called (under the store's lock: it must be quick) for every new stream message.
  void set_listener(std::function<void()> listener);

 private:
  template <class T>
  struct Stamped {
    std::int64_t utc_ns = 0;
    T value;
  };
  struct Unit {
    Unit(std::size_t health_capacity, std::size_t attitude_capacity, std::size_t event_capacity)
        : health(health_capacity), attitude(attitude_capacity), events(event_capacity) {}
    RingBuffer<Stamped<dds::HealthView>> health;
    RingBuffer<Stamped<fdi::AttitudeEstimate>> attitude;
    RingBuffer<Stamped<dds::EventView>> events;
    std::optional<std::int64_t> health_received_ns;    //!< [ns] monotonic
    std::optional<std::int64_t> attitude_received_ns;  //!< [ns] monotonic
    std::optional<std::int64_t> last_kept_stamp_ns;    //!< [ns] sensor time of the last attitude kept
    bool writer_alive = true;
    Link link = Link::kWaiting;
    std::int64_t link_streamed_ns = 0;
  };

  //! The unit's record, created on first sight; nullptr beyond max_units.
  Unit* unit(const std::string& name);
  nlohmann::json link_json(const std::string& name, const Unit& u, std::int64_t now_ns) const;
  void stream(const char* event, const nlohmann::json& data);
  int gyro_count(const Unit& u) const;

  StoreConfig config_;
  std::int64_t attitude_period_ns_;
  mutable std::mutex mutex_;
  mutable std::condition_variable arrived_;
  std::map<std::string, Unit> units_;
  RingBuffer<StreamMessage> stream_;
  std::uint64_t next_id_ = 1;
  std::function<void()> listener_;
};

}  // namespace tetra::ground
