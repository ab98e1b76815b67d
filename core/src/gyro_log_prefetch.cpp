#include "tetra/core/gyro_log_prefetch.hpp"

namespace tetra {

GyroLogPrefetcher::GyroLogPrefetcher(std::unique_ptr<GyroLogReader> reader)
    : reader_(std::move(reader)), worker_([this] { run(); }) {}

GyroLogPrefetcher::~GyroLogPrefetcher() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

void GyroLogPrefetcher::run() {
  while (true) {
    Item item;
    {
      const std::lock_guard lock(mutex_);
      if (!spare_.empty()) {
        item.block = std::move(spare_.back());
        spare_.pop_back();
      }
    }
    item.more = reader_->next(item.block);
    fraction_.store(reader_->fraction_read(), std::memory_order_relaxed);
    const bool last = !item.more || !*item.more;
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return stop_ || queue_.size() < kDepth; });
    if (stop_) return;
    queue_.push_back(std::move(item));
    lock.unlock();
    changed_.notify_all();
    if (last) return;
  }
}

Result<bool> GyroLogPrefetcher::next(GyroLog& block) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return !queue_.empty(); });
  Item item = std::move(queue_.front());
  queue_.pop_front();
  // The end (or an error) stays at the head, so every later call returns it again.
  const bool last = !item.more || !*item.more;
  if (last) {
    queue_.push_front(Item{item.more, GyroLog{}});
  } else {
    if (spare_.size() < kDepth) spare_.push_back(std::move(block));
    block = std::move(item.block);
  }
  lock.unlock();
  changed_.notify_all();
  return item.more;
}

}  // namespace tetra
