// Child processes (tetra/dds_tools/child_process.hpp).
#include "tetra/dds_tools/child_process.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

namespace tetra::dds_tools {

int ChildProcess::stop(int grace_ms) {
  if (pid_ <= 0) return status_;
  kill(pid_, SIGTERM);
  for (int waited = 0; waited < grace_ms; waited += 10) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      return status_;
    }
    usleep(10'000);  // a child's exit cannot be put on a DDS waitset
  }
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
  return status_;
}

int ChildProcess::wait() {
  if (pid_ <= 0) return status_;
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return status_;
}

}  // namespace tetra::dds_tools
