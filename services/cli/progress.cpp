#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace tetra::cli {

namespace {
constexpr std::chrono::milliseconds kQuiet{2000};  // runs shorter than this print nothing
constexpr std::chrono::milliseconds kRedraw{500};  // at most two redraws a second
}  // namespace

Progress::Progress(std::string command, std::string unit)
    : command_(std::move(command)),
      unit_(std::move(unit)),
      enabled_(::isatty(STDERR_FILENO) == 1),
      start_(Clock::now()),
      last_(start_) {}

void Progress::update(double fraction, std::size_t count) {
  if (!enabled_) return;
  const auto now = Clock::now();
  if (now - start_ < kQuiet || now - last_ < kRedraw) return;
  last_ = now;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double rate = static_cast<double>(count) / elapsed_s;
  const double left_s = fraction > 0.0 ? elapsed_s * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "\r%s: %3.0f %%, %.2f M %s/s, %.0f s left   ", command_.c_str(), 100.0 * fraction,
               rate * 1e-6, unit_.c_str(), left_s);
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::finish() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace tetra::cli
