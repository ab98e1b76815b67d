#pragma once
// A child process, terminated (SIGTERM, then SIGKILL) when its handle goes out of scope; and the running
// program started again as a child (`tetra fusion` for a demo or a DDS campaign's run).

#include <string>
#include <vector>

namespace tetra::dds_tools {

//! Path of the running program (/proc/self/exe).
std::string self_executable();

//! Starts `self_executable() args...` as a child with SIGINT/SIGTERM unblocked; stdout/stderr
//! go to the given files (empty: inherited); the child gets SIGTERM when the calling thread ends
//! (PR_SET_PDEATHSIG: call it from the thread that outlives the child). Returns the pid, or -1.
int spawn_self(const std::vector<std::string>& args, const std::string& stdout_path = "",
               const std::string& stderr_path = "");

class ChildProcess {
 public:
  explicit ChildProcess(int pid) : pid_(pid) {}
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() { stop(); }
  int pid() const { return pid_; }
  //! SIGTERM, wait up to `grace_ms`, then SIGKILL. Returns the exit status (-1 if killed).
  int stop(int grace_ms = 3000);
  //! Waits for a child that ends by itself; its exit status (-1 if killed).
  int wait();

 private:
  int pid_ = -1;
  int status_ = -1;
};

}  // namespace tetra::dds_tools
