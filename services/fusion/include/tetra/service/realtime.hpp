#pragma once
// `tetra fusion --realtime` (docs/dds.md, "Real-time scheduling"): the process's memory locked
// (mlockall, no page fault on the step's path) and the threads that receive samples and step the
// pipeline under SCHED_FIFO, each where the system allows it. Each returns what failed, naming the call
// and the reason (no privilege: CAP_IPC_LOCK or RLIMIT_MEMLOCK for the first, CAP_SYS_NICE or
// RLIMIT_RTPRIO for the second), for the caller to warn about and go on.

#include "tetra/core/result.hpp"

namespace tetra::service {

inline constexpr int kMinRealtimePriority = 1;  //!< SCHED_FIFO's range on Linux
inline constexpr int kMaxRealtimePriority = 99;

//! mlockall(MCL_CURRENT | MCL_FUTURE).
Status lock_memory();
//! SCHED_FIFO at `priority` for the calling thread.
Status make_thread_realtime(int priority);

}  // namespace tetra::service
