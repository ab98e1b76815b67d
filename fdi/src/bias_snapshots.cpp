#include "bias_snapshots.hpp"

#include <algorithm>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

BiasSnapshots::BiasSnapshots(const Mekf& filter)
    : size_(static_cast<std::size_t>(filter.saved_size())),
      data_(static_cast<std::size_t>(kCopies) * size_, 0.0),
      stamp_ns_(kCopies, 0) {}

void BiasSnapshots::reset() {
  count_ = 0;
  release();
}

void BiasSnapshots::take(std::int64_t now_ns, const Mekf& filter) {
  if (holding_) return;
  if (count_ > 0 && now_ns - stamp_ns_[static_cast<std::size_t>((count_ - 1) % kCopies)] < kSpacing_ns)
    return;
  filter.save_biases(copy(count_));
  stamp_ns_[static_cast<std::size_t>(count_ % kCopies)] = now_ns;
  ++count_;
}

int BiasSnapshots::newest_before(std::int64_t t_ns) const {
  for (int k = count_ - 1; k >= std::max(0, count_ - kCopies); --k) {
    if (stamp_ns_[static_cast<std::size_t>(k % kCopies)] <= t_ns) return k;
  }
  return -1;
}

void BiasSnapshots::hold(std::int64_t onset_ns) {
  if (holding_) return;
  holding_ = true;
  held_ = newest_before(onset_ns);
}

void BiasSnapshots::restore(Mekf& filter, GyroMask gyros, std::int64_t onset_ns, std::int64_t now_ns) {
  const int k = holding_ ? held_ : newest_before(onset_ns);
  if (k >= 0) {
    filter.restore_biases(copy(k), gyros,
                          ns_to_seconds(now_ns - stamp_ns_[static_cast<std::size_t>(k % kCopies)]));
  } else {
    filter.restore_prior(gyros);
  }
  release();
}

}  // namespace tetra::fdi::detail
