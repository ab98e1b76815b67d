#pragma once
// A child process, terminated (SIGTERM, then SIGKILL) when its handle goes out of scope.

namespace tetra::dds_tools {

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
