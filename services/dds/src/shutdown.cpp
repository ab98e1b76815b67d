#include "tetra/dds/shutdown.hpp"

#include <pthread.h>
#include <signal.h>

namespace tetra::dds {

namespace {
sigset_t shutdown_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}
}  // namespace

ShutdownSignal::ShutdownSignal() {
  const sigset_t set = shutdown_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  thread_ = std::thread([this] {
    const sigset_t waited = shutdown_signals();
    int number = 0;
    while (sigwait(&waited, &number) == 0) {
      if (stopping_.load()) return;
      signal_.store(number);
      requested_.store(true);
      const dds_entity_t guard = guard_.load();
      if (guard > 0) (void)dds_set_guardcondition(guard, true);
    }
  });
}

ShutdownSignal::~ShutdownSignal() {
  stopping_.store(true);
  // Wake the sigwait() of our own thread only (the process-wide mask stays as it was set).
  pthread_kill(thread_.native_handle(), SIGTERM);
  thread_.join();
  const sigset_t set = shutdown_signals();
  pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
}

}  // namespace tetra::dds
