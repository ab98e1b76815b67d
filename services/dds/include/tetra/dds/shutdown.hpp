#pragma once
// Clean shutdown on SIGINT/SIGTERM for waitset-driven loops.
//
// Construct ShutdownSignal FIRST in main-like code, before any DDS entity exists: it blocks SIGINT
// and SIGTERM in the calling thread, so every thread created afterwards (Cyclone's included)
// inherits the mask, and a dedicated thread receives them with sigwait(). When one arrives, that
// thread sets the flag and triggers the attached guard condition, waking the waitset — no polling,
// and nothing async-signal-unsafe runs in a signal handler.

#include <atomic>
#include <thread>

#include <dds/dds.h>

namespace tetra::dds {

class ShutdownSignal {
 public:
  ShutdownSignal();
  ~ShutdownSignal();
  ShutdownSignal(const ShutdownSignal&) = delete;
  ShutdownSignal& operator=(const ShutdownSignal&) = delete;

  //! Guard condition to trigger on a signal (may be set once the participant exists).
  void set_guard(dds_entity_t guard_condition) { guard_.store(guard_condition); }
  bool requested() const { return requested_.load(); }
  int signal_number() const { return signal_.load(); }

 private:
  std::atomic<dds_entity_t> guard_{0};
  std::atomic<bool> requested_{false};
  std::atomic<bool> stopping_{false};
  std::atomic<int> signal_{0};
  std::thread thread_;
};

}  // namespace tetra::dds
