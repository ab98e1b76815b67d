#pragma once
// The recorder's gyro samples in time order across takes. A reader's take returns one gyro's samples after
// another's, so with a writer faster than real time (ingest of a file, play --speed max) or a recorder that
// was paused, one gyro's newest stamp runs hundreds of periods ahead of another's next one and the epoch
// assembler would judge the late gyro's samples time outliers. The merge holds each sample until no gyro
// can still deliver an earlier stamp (every gyro's newest stamp taken is at least its own), or for at most
// `hold_ns` (a gyro gone silent never holds the others back), and hands them on in stamp order.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "tetra/dds/topics.hpp"

namespace tetra::dds_tools {

class SampleMerge {
 public:
  SampleMerge(int gyro_count, std::int64_t hold_ns)
      : newest_(static_cast<std::size_t>(gyro_count) + 1, std::numeric_limits<std::int64_t>::min()),
        hold_ns_(hold_ns) {}

  //! A sample taken at local time `now` [ns].
  void add(const tetra_GyroSample& s, std::int64_t now) {
    if (s.gyro >= 1 && s.gyro < newest_.size())
      newest_[s.gyro] = std::max(newest_[s.gyro], static_cast<std::int64_t>(s.stamp_ns));
    held_.push_back({s, now});
    sorted_ = false;
  }
  //! Gives `give(sample)` the samples due by local time `now` (all of them with `flush`), in stamp order.
  template <class Give>
  void release(std::int64_t now, bool flush, Give&& give) {
    if (held_.empty()) return;
    if (!sorted_) {
      std::stable_sort(held_.begin(), held_.end(),
                       [](const Held& a, const Held& b) { return a.sample.stamp_ns < b.sample.stamp_ns; });
      sorted_ = true;
    }
    std::int64_t upto = *std::min_element(newest_.begin() + 1, newest_.end());
    for (const Held& h : held_) {
      if (flush || now - h.arrived_ns >= hold_ns_)
        upto = std::max(upto, static_cast<std::int64_t>(h.sample.stamp_ns));
    }
    std::size_t n = 0;
    while (n < held_.size() && (flush || static_cast<std::int64_t>(held_[n].sample.stamp_ns) <= upto))
      give(held_[n++].sample);
    held_.erase(held_.begin(), held_.begin() + static_cast<std::ptrdiff_t>(n));
  }
  //! Local time [ns] the oldest sample held is due, or nullopt.
  std::optional<std::int64_t> next_due_ns() const {
    if (held_.empty()) return std::nullopt;
    std::int64_t oldest = held_.front().arrived_ns;
    for (const Held& h : held_) oldest = std::min(oldest, h.arrived_ns);
    return oldest + hold_ns_;
  }

 private:
  struct Held {
    tetra_GyroSample sample;
    std::int64_t arrived_ns;
  };
  std::vector<std::int64_t> newest_;  // per gyro id 1..N: the newest stamp taken
  std::vector<Held> held_;
  bool sorted_ = true;
  std::int64_t hold_ns_;
};

}  // namespace tetra::dds_tools
