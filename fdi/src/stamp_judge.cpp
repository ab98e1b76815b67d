#include "stamp_judge.hpp"

#include <limits>

namespace tetra::fdi::detail {

std::int64_t StampJudge::window_ns() const {
  // Saturated: a period near the int64 range (1000 periods of ~1e7 s) never overflows the window.
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max() / 4;
  return period_ns_ > kMax / design::stamp_window_periods ? kMax : period_ns_ * design::stamp_window_periods;
}

StampVerdict StampJudge::judge(std::int64_t stamp_ns) {
  if (!last_ns_) {
    last_ns_ = stamp_ns;
    return StampVerdict::kAccepted;
  }
  const std::int64_t last = *last_ns_;
  if (period_ns_ <= 0) {  // no period yet: only the order is judged
    if (stamp_ns <= last) return StampVerdict::kNotIncreasing;
    last_ns_ = stamp_ns;
    return StampVerdict::kAccepted;
  }
  const std::int64_t window = window_ns();
  // Differences in long double: stamps anywhere in int64 never overflow the comparison.
  const long double ahead = static_cast<long double>(stamp_ns) - static_cast<long double>(last);
  if (ahead > 0 && ahead <= static_cast<long double>(window)) {
    last_ns_ = stamp_ns;
    candidate_ns_.reset();  // a stamp on the stream's time: the outliers were not a jump
    candidate_count_ = 0;
    return StampVerdict::kAccepted;
  }
  if (ahead <= 0) {
    return ahead >= -static_cast<long double>(window) ? StampVerdict::kNotIncreasing : StampVerdict::kOutlier;
  }
  // Far ahead: an outlier, unless it continues a run of forward outliers that agree with each other.
  const bool agrees = candidate_ns_ && stamp_ns > *candidate_ns_ &&
                      static_cast<long double>(stamp_ns) - static_cast<long double>(*candidate_ns_) <=
                          static_cast<long double>(window);
  candidate_count_ = agrees ? candidate_count_ + 1 : 1;
  candidate_ns_ = stamp_ns;
  if (candidate_count_ < design::stamp_confirm_count) return StampVerdict::kOutlier;
  last_ns_ = stamp_ns;  // the stream's time jumped for good: a gap
  candidate_ns_.reset();
  candidate_count_ = 0;
  return StampVerdict::kAccepted;
}

void StampJudge::reset() {
  last_ns_.reset();
  candidate_ns_.reset();
  candidate_count_ = 0;
}

}  // namespace tetra::fdi::detail
