#include "tetra/service/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace tetra::service {

namespace {

std::string reason(int error) {
  switch (error) {
    case EPERM:
      return "not permitted (" + std::string(std::strerror(error)) + ")";
    case ENOMEM:
      return "over the locked-memory limit (" + std::string(std::strerror(error)) + ")";
    default:
      return std::strerror(error);
  }
}

}  // namespace

Status lock_memory() {
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return ok_status();
  const int error = errno;
  return failure("mlockall(MCL_CURRENT | MCL_FUTURE) failed: " + reason(error) +
                 "; memory stays pageable (needs CAP_IPC_LOCK or a larger RLIMIT_MEMLOCK, ulimit -l)");
}

Status make_thread_realtime(int priority) {
  if (priority < kMinRealtimePriority || priority > kMaxRealtimePriority) {
    return bad_input("SCHED_FIFO priority " + std::to_string(priority) + " is outside " +
                     std::to_string(kMinRealtimePriority) + ".." + std::to_string(kMaxRealtimePriority));
  }
  sched_param param{};
  param.sched_priority = priority;
  const int error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param);
  if (error == 0) return ok_status();
  return failure("pthread_setschedparam(SCHED_FIFO, " + std::to_string(priority) +
                 ") failed: " + reason(error) +
                 "; the thread keeps the default scheduling (needs CAP_SYS_NICE or RLIMIT_RTPRIO, "
                 "ulimit -r)");
}

}  // namespace tetra::service
