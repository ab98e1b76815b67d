#include "tetra/report/progress.hpp"

#include <cstdio>

namespace tetra::report {

namespace {
constexpr std::chrono::milliseconds kQuiet{2000};  // runs shorter than this print nothing
constexpr std::chrono::milliseconds kRedraw{500};  // at most two redraws a second
}  // namespace

Progress::Progress(std::string command, std::string unit, std::FILE* terminal)
    : command_(std::move(command)),
      unit_(std::move(unit)),
      terminal_(terminal),
      start_(Clock::now()),
      last_(start_) {}

void Progress::update(double fraction, std::size_t count) {
  if (terminal_ == nullptr) return;
  const auto now = Clock::now();
  if (now - start_ < kQuiet || now - last_ < kRedraw) return;
  last_ = now;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double rate = static_cast<double>(count) / elapsed_s;
  const double left_s = fraction > 0.0 ? elapsed_s * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(terminal_, "\r%s: %3.0f %%, %.2f M %s/s, %.0f s left   ", command_.c_str(), 100.0 * fraction,
               rate * 1e-6, unit_.c_str(), left_s);
  std::fflush(terminal_);
  drawn_ = true;
}

void Progress::finish() {
  if (!drawn_) return;
  std::fprintf(terminal_, "\r\033[K");
  std::fflush(terminal_);
  drawn_ = false;
}

}  // namespace tetra::report
