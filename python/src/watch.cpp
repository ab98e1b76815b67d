#include "watch.hpp"

#include <utility>

namespace tetra::python {

namespace {

constexpr auto kSignalsEvery = std::chrono::milliseconds(10);
constexpr auto kProgressEvery = std::chrono::milliseconds(100);

}  // namespace

Watch::Watch(py::object progress)
    : progress_(std::move(progress)),
      last_signals_(std::chrono::steady_clock::now()),
      last_progress_(last_signals_) {}

Interrupt Watch::interrupt() {
  return Interrupt([this](std::size_t done, std::size_t total) { return poll(done, total); });
}

bool Watch::poll(std::size_t done, std::size_t total) {
  if (error_) return true;
  const auto now = std::chrono::steady_clock::now();
  const bool signals = now - last_signals_ >= kSignalsEvery;
  const bool report = !progress_.is_none() && now - last_progress_ >= kProgressEvery;
  if (!signals && !report) return false;
  py::gil_scoped_acquire gil;
  last_signals_ = now;
  if (PyErr_CheckSignals() != 0) {
    error_.emplace();  // fetches the handler's exception (KeyboardInterrupt)
    return true;
  }
  if (report) {
    last_progress_ = now;
    try {
      progress_(done, total);
    } catch (py::error_already_set& e) {
      error_.emplace(std::move(e));
      return true;
    }
  }
  return false;
}

void Watch::raise_if_stopped() const {
  if (error_) throw *error_;
}

void Watch::done(std::size_t done, std::size_t total) const {
  if (!progress_.is_none()) progress_(done, total);
}

py::object Watch::pending() const {
  if (!error_) return py::none();
  return error_->value();
}

}  // namespace tetra::python
