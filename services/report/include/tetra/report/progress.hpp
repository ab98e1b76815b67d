#pragma once
// Progress of a long run on a terminal: percentage, rate and time left, redrawn in place at most twice a
// second once the run has lasted two seconds. Silent without a terminal (the caller passes none for
// pipes, files, tests).

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace tetra::report {

class Progress {
 public:
  //! `command` names the line ("tetra replay"); `unit` what is counted ("epochs"); `terminal` is where
  //! the line is drawn (a terminal's stream, e.g. stderr when isatty), nullptr for none.
  Progress(std::string command, std::string unit, std::FILE* terminal);
  //! `fraction` of the work done (0..1), `count` items so far.
  void update(double fraction, std::size_t count);
  //! Clears the line if one was drawn.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::string command_;
  std::string unit_;
  std::FILE* terminal_ = nullptr;
  bool drawn_ = false;
  Clock::time_point start_;
  Clock::time_point last_;
};

}  // namespace tetra::report
