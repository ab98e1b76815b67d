#include "tetra/ground/command_tracker.hpp"

#include <atomic>

namespace tetra::ground {

void CommandTracker::expect(std::uint64_t command_id, const std::string& unit) {
  const std::lock_guard lock(mutex_);
  pending_[command_id] = Pending{unit, std::nullopt};
}

bool CommandTracker::offer(const dds::EventView& event) {
  if (event.command_id == 0) return false;
  {
    const std::lock_guard lock(mutex_);
    auto it = pending_.find(event.command_id);
    if (it == pending_.end() || it->second.unit != event.unit || it->second.ack) return false;
    it->second.ack = event;
  }
  answered_.notify_all();
  return true;
}

std::optional<dds::EventView> CommandTracker::wait(std::uint64_t command_id,
                                                   std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  auto it = pending_.find(command_id);
  if (it == pending_.end()) return std::nullopt;
  answered_.wait_for(lock, timeout, [&] { return it->second.ack.has_value(); });
  auto ack = std::move(it->second.ack);
  pending_.erase(it);
  return ack;
}

std::size_t CommandTracker::pending() const {
  const std::lock_guard lock(mutex_);
  return pending_.size();
}

std::uint64_t new_command_id(std::int64_t wall_ns, int pid) {
  static std::atomic<std::uint64_t> counter{0};
  const std::uint64_t mixed = (static_cast<std::uint64_t>(wall_ns) << 16) ^ static_cast<std::uint64_t>(pid) ^
                              (counter.fetch_add(1) << 48);
  return mixed == 0 ? 1 : mixed;
}

}  // namespace tetra::ground
