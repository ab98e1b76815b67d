#pragma once
// How a long library call hears from its caller while it runs: a callback the call polls between its
// steps with the work done so far. Answering true stops the call at that step: it returns interrupted()
// and keeps no partial result. What answers is the caller's business (a signal flag, a cancel button, an
// interpreter's pending KeyboardInterrupt): the library only asks.
#include <cstddef>
#include <functional>
#include <utility>

#include "tetra/core/result.hpp"

namespace tetra {

class Interrupt {
 public:
  //! `done` steps of `total` (0: not known); true: stop.
  using Poll = std::function<bool(std::size_t done, std::size_t total)>;

  Interrupt() = default;
  explicit Interrupt(Poll poll) : poll_(std::move(poll)) {}

  //! Asks the caller; once it has answered true, true without asking again.
  bool requested(std::size_t done, std::size_t total) {
    if (!stopped_ && poll_ && poll_(done, total)) stopped_ = true;
    return stopped_;
  }
  //! Whether a poll has asked to stop.
  bool stopped() const { return stopped_; }

 private:
  Poll poll_;
  bool stopped_ = false;
};

//! Whether `interrupt` (optional) asks to stop after `done` of `total` steps.
inline bool interrupt_requested(Interrupt* interrupt, std::size_t done, std::size_t total) {
  return interrupt != nullptr && interrupt->requested(done, total);
}
//! The error of a call its Interrupt stopped.
inline Error interrupted() {
  return failure("interrupted");
}

}  // namespace tetra
