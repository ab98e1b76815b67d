#pragma once
// A `tetra` command run as a child process by a test (DDS services, simulators, monitors): its
// stdout and stderr go to a log file, and it is SIGKILLed and reaped when the object goes out of
// scope, so a failing test never leaves processes behind.

#include <sys/types.h>

#include <string>
#include <vector>

namespace tetra::test {

class TetraProcess {
 public:
  //! Starts `tetra ARGS...` with stdout and stderr to `log_path`.
  TetraProcess(const std::vector<std::string>& args, const std::string& log_path);
  TetraProcess(const TetraProcess&) = delete;
  TetraProcess& operator=(const TetraProcess&) = delete;
  ~TetraProcess();

  //! Sends `sig` and reaps the process without looking at how it ended.
  void kill_now(int sig);
  //! Sends `sig` and waits; returns the exit status (-1: ended by a signal, or not running).
  int signal_and_wait(int sig);
  //! Waits for the process to end by itself; returns its exit status (-1 as above).
  int wait_exit();
  //! Sends `sig` and returns at once (SIGSTOP / SIGCONT: pausing the process).
  void signal(int sig) const;

 private:
  pid_t pid_ = -1;
};

//! Points CYCLONEDDS_URI at the repository's loopback-only configuration, for this process and every
//! child it starts. Call before creating any DDS entity (a static initializer in each DDS test).
bool use_loopback_dds();

}  // namespace tetra::test
