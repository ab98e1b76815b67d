#pragma once
// Progress of a long run on stderr, for a terminal only: percentage, rate and time left, redrawn in
// place at most twice a second once the run has lasted two seconds. Silent when stderr is not a
// terminal (pipes, files, tests).

#include <chrono>
#include <cstddef>
#include <string>

namespace tetra::cli {

class Progress {
 public:
  //! `command` names the line ("tetra replay"); `unit` what is counted ("epochs").
  Progress(std::string command, std::string unit);
  //! `fraction` of the work done (0..1), `count` items so far.
  void update(double fraction, std::size_t count);
  //! Clears the line if one was drawn.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::string command_;
  std::string unit_;
  bool enabled_ = false;
  bool drawn_ = false;
  Clock::time_point start_;
  Clock::time_point last_;
};

}  // namespace tetra::cli
