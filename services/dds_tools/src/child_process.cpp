// Child processes (tetra/dds_tools/child_process.hpp).
#include "tetra/dds_tools/child_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

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

std::string self_executable() {
  return std::filesystem::read_symlink("/proc/self/exe").string();
}

int spawn_self(const std::vector<std::string>& args, const std::string& stdout_path,
               const std::string& stderr_path) {
  const std::string exe = self_executable();
  std::vector<std::string> storage;
  storage.push_back(exe);
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid != 0) return pid;  // parent (or -1)
  // Child: signal mask and redirections, then exec. Only async-signal-safe calls from here on.
  // The child is stopped (SIGTERM) when the process that started it ends, however it ends: a campaign
  // worker or a demo killed by a signal leaves no service behind.
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (getppid() != parent) _exit(127);  // it ended before the line above
  sigset_t set;
  sigemptyset(&set);
  sigprocmask(SIG_SETMASK, &set, nullptr);
  if (!stdout_path.empty()) {
    const int fd = open(stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, STDOUT_FILENO);
  }
  if (!stderr_path.empty()) {
    const int fd = open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, STDERR_FILENO);
  }
  execv(exe.c_str(), argv.data());
  _exit(127);
}

}  // namespace tetra::dds_tools
