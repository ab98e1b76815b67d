#pragma once
// A bounded first-in first-out buffer: the newest `capacity` items, memory allocated once.

#include <cstddef>
#include <vector>

namespace tetra::ground {

template <class T>
class RingBuffer {
 public:
  explicit RingBuffer(std::size_t capacity) : slots_(capacity == 0 ? 1 : capacity) {}

  //! Appends `item`; when full, the oldest item is dropped.
  void push(T item) {
    slots_[(first_ + size_) % slots_.size()] = std::move(item);
    if (size_ < slots_.size()) {
      ++size_;
    } else {
      first_ = (first_ + 1) % slots_.size();
      ++dropped_;
    }
  }

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return slots_.size(); }
  bool empty() const { return size_ == 0; }
  //! Items pushed out by newer ones since construction.
  std::size_t dropped() const { return dropped_; }

  //! The i-th oldest item (0: the oldest).
  const T& operator[](std::size_t i) const { return slots_[(first_ + i) % slots_.size()]; }
  const T& newest() const { return (*this)[size_ - 1]; }

  //! Index of the first item for which `before(item)` is false (items ordered by `before`).
  template <class Pred>
  std::size_t partition_point(Pred before) const {
    std::size_t lo = 0;
    std::size_t hi = size_;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (before((*this)[mid])) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  }

 private:
  std::vector<T> slots_;
  std::size_t first_ = 0;
  std::size_t size_ = 0;
  std::size_t dropped_ = 0;
};

}  // namespace tetra::ground
