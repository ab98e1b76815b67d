#pragma once
// Reads a gyro log's blocks ahead on a worker thread, so that parsing (or decompressing) the next
// block overlaps the caller's work on this one. At most kDepth blocks wait in memory.

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "tetra/core/gyro_log.hpp"
#include "tetra/core/result.hpp"

namespace tetra {

class GyroLogPrefetcher {
 public:
  static constexpr std::size_t kDepth = 2;

  //! Starts reading `reader` ahead.
  explicit GyroLogPrefetcher(std::unique_ptr<GyroLogReader> reader);
  GyroLogPrefetcher(const GyroLogPrefetcher&) = delete;
  GyroLogPrefetcher& operator=(const GyroLogPrefetcher&) = delete;
  //! Stops the worker (a block being read is finished first).
  ~GyroLogPrefetcher();

  const GyroLog& header() const { return reader_->header(); }
  //! As GyroLogReader::next, in the same order, with the same errors. The block passed in goes back to
  //! the worker to be filled again (its buffers are reused: no allocation per block).
  Result<bool> next(GyroLog& block);
  //! Fraction of the log read by the worker so far.
  double fraction_read() const { return fraction_.load(std::memory_order_relaxed); }

 private:
  struct Item {
    Result<bool> more = false;
    GyroLog block;
  };
  void run();

  std::unique_ptr<GyroLogReader> reader_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> queue_;
  std::vector<GyroLog> spare_;  // blocks handed back, to be refilled
  bool stop_ = false;
  std::atomic<double> fraction_{0.0};
  std::thread worker_;
};

}  // namespace tetra
