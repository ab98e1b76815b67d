#pragma once
// Matches operator commands with their acknowledgements: the HTTP thread that sent a command waits
// here for the FdiEvent carrying its command id (and unit), which the DDS thread hands in.
// Acknowledgements of commands nobody waits for (sent by other clients) are ignored.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "tetra/dds/convert.hpp"

namespace tetra::ground {

class CommandTracker {
 public:
  //! Registers a command about to be sent (before sending: the answer may come at once).
  void expect(std::uint64_t command_id, const std::string& unit);
  //! An FdiEvent from the DDS thread; true when it answered an expected command.
  bool offer(const dds::EventView& event);
  //! The acknowledgement, or nullopt after `timeout`; the command is forgotten either way.
  std::optional<dds::EventView> wait(std::uint64_t command_id, std::chrono::milliseconds timeout);
  //! Commands registered and not yet collected by wait().
  std::size_t pending() const;

 private:
  struct Pending {
    std::string unit;
    std::optional<dds::EventView> ack;
  };
  mutable std::mutex mutex_;
  std::condition_variable answered_;
  std::map<std::uint64_t, Pending> pending_;
};

//! A command id unlikely to collide with another client's: wall-clock ns mixed with the process id
//! and a counter.
std::uint64_t new_command_id(std::int64_t wall_ns, int pid);

}  // namespace tetra::ground
