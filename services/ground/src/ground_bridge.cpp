#include "tetra/ground/ground_bridge.hpp"

#include <unistd.h>

#include <thread>

namespace tetra::ground {

namespace {
constexpr std::chrono::milliseconds kLinkRefresh{100};  //!< link states re-evaluated this often
}

Status GroundBridge::take_all(std::int64_t now_ns) {
  auto h = readers_.take_health(
      [&](dds::HealthView&& health, std::int64_t utc_ns) { store_.add_health(health, utc_ns, now_ns); },
      [&](const std::string& unit) { store_.set_writer_alive(unit, false, now_ns); });
  if (!h) return h;
  auto e = readers_.take_events([&](dds::EventView&& event, std::int64_t utc_ns) {
    (void)tracker_.offer(event);
    store_.add_event(event, utc_ns);
  });
  if (!e) return e;
  return readers_.take_attitudes(
      [&](const std::string& unit, fdi::AttitudeEstimate&& attitude, std::int64_t utc_ns) {
        store_.add_attitude(unit, attitude, utc_ns, now_ns);
      });
}

Status GroundBridge::run(const dds::ShutdownSignal& shutdown) {
  std::vector<std::intptr_t> triggered;
  while (!shutdown.requested()) {
    if (auto s = readers_.wait(kLinkRefresh, triggered); !s) return s;
    const std::int64_t now = steady_now_ns();
    if (auto s = take_all(now); !s) return s;
    store_.update_links(now);
  }
  return ok_status();
}

Result<dds::EventView> GroundBridge::send(const CommandRequest& request, std::chrono::milliseconds timeout) {
  const std::int64_t wall = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::system_clock::now().time_since_epoch())
                                .count();
  const std::uint64_t id = new_command_id(wall, static_cast<int>(getpid()));
  tetra_Command wire{};
  if (auto s = to_wire(request, id, wire); !s) return s.error();
  {
    const std::lock_guard lock(write_mutex_);
    auto matched = readers_.command_writer().matched_readers();
    if (!matched) return matched.error();
    if (*matched == 0) return failure("no fusion service is listening for commands");
    tracker_.expect(id, request.unit);
    if (auto s = readers_.command_writer().write(wire); !s) {
      (void)tracker_.wait(id, std::chrono::milliseconds(0));
      return s.error();
    }
  }
  auto ack = tracker_.wait(id, timeout);
  if (!ack) {
    return failure("no acknowledgement from unit " + request.unit + " within " +
                   std::to_string(timeout.count()) + " ms");
  }
  return std::move(ack).value();
}

}  // namespace tetra::ground
