#pragma once
// A long call's link to Python while the library works with the GIL released (docs/python.md,
// "Ctrl-C and progress"): the library polls a tetra::Interrupt; at most every 10 ms the poll takes the
// GIL and runs Python's signal handlers (Ctrl-C raises KeyboardInterrupt there), and at most every 0.1 s
// it calls the progress callback. An exception from either stops the call; finish() raises it.
#include <chrono>
#include <cstddef>
#include <optional>

#include "common.hpp"
#include "tetra/core/interrupt.hpp"

namespace tetra::python {

class Watch {
 public:
  //! `progress`: None, or a callable progress(done, total) (the package makes one of a tqdm bar).
  explicit Watch(py::object progress);
  Watch(const Watch&) = delete;
  Watch& operator=(const Watch&) = delete;

  //! The library's Interrupt over this watch: poll it from the thread that called into the module.
  Interrupt interrupt();
  //! Called with the GIL released: true once a signal handler or the callback raised.
  bool poll(std::size_t done, std::size_t total);
  //! Whether an exception stopped the call.
  bool stopped() const { return error_.has_value(); }
  //! With the GIL: raises the exception that stopped the call, if one did.
  void raise_if_stopped() const;
  //! With the GIL, once the call is over: the callback's last report (`done` of `total`).
  void done(std::size_t done, std::size_t total) const;
  //! With the GIL: the exception that stopped the call (None if none), for a caller that returns the
  //! partial results with it.
  py::object pending() const;

 private:
  py::object progress_;
  std::chrono::steady_clock::time_point last_signals_;
  std::chrono::steady_clock::time_point last_progress_;
  std::optional<py::error_already_set> error_;
};

}  // namespace tetra::python
