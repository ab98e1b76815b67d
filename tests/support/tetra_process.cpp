#include "tetra_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "test_support.hpp"

namespace tetra::test {

namespace {
int exit_status(int status) {
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
}  // namespace

TetraProcess::TetraProcess(const std::vector<std::string>& args, const std::string& log_path) {
  std::vector<std::string> storage{TETRA_BINARY};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;  // built before fork(): the child of a threaded process must not allocate
  argv.reserve(storage.size() + 1);
  for (auto& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);  // or the child would inherit our buffered output
  pid_ = fork();
  if (pid_ == 0) {
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
    }
    execv(TETRA_BINARY, argv.data());
    _exit(127);
  }
}

TetraProcess::~TetraProcess() {
  kill_now(SIGKILL);
}

void TetraProcess::signal(int sig) const {
  if (pid_ > 0) ::kill(pid_, sig);
}

void TetraProcess::kill_now(int sig) {
  if (pid_ <= 0) return;
  ::kill(pid_, sig);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

int TetraProcess::signal_and_wait(int sig) {
  if (pid_ <= 0) return -1;
  ::kill(pid_, sig);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return exit_status(status);
}

int TetraProcess::wait_exit() {
  if (pid_ <= 0) return -1;
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return exit_status(status);
}

bool use_loopback_dds() {
  const std::string uri = "file://" + source_path("config/cyclonedds-loopback.xml");
  return setenv("CYCLONEDDS_URI", uri.c_str(), 1) == 0;
}

}  // namespace tetra::test
