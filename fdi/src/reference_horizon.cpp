#include "reference_horizon.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

void ReferenceHorizon::prepare(double period_s) {
  const std::int64_t period_ns = seconds_to_ns(period_s);
  if (period_ns <= 0 || period_ns == period_ns_) return;
  period_ns_ = period_ns;
  // One entry per epoch of the horizon, and two more: the epoch at its far edge and a jittered stamp.
  const double epochs = std::ceil(horizon_s_ / period_s);
  const std::size_t size = horizon_s_ > 0.0 && epochs < 1e6 ? static_cast<std::size_t>(epochs) + 2 : 0;
  ring_.assign(size, Entry{});
  head_ = 0;
  count_ = 0;
  // The epochs before the period was known (the first one): the newest stays buffered.
  if (has_final_ && !ring_.empty()) {
    ring_[0] = newest_;
    count_ = 1;
  }
}

void ReferenceHorizon::reset() {
  late_run_ = false;
  head_ = 0;
  count_ = 0;
  has_final_ = false;
  gyro_RB_ = Quaternion::Identity();
}

void ReferenceHorizon::record(std::int64_t stamp_ns, const Quaternion& q_propagated_RB,
                              const Quaternion& q_final_RB) {
  if (has_final_) gyro_RB_ = (gyro_RB_ * (last_final_RB_.conjugate() * q_propagated_RB)).normalized();
  last_final_RB_ = q_final_RB;
  has_final_ = true;
  newest_ = {stamp_ns, gyro_RB_};
  if (ring_.empty()) return;
  if (++head_ == ring_.size()) head_ = 0;  // the ring's next slot (no division at every epoch)
  ring_[head_] = newest_;
  if (count_ < ring_.size()) ++count_;
}

PlacedReference ReferenceHorizon::place(std::int64_t ref_ns, const Quaternion& q_ref_RB, std::int64_t now_ns,
                                        const Eigen::Vector3d& omega_BR_B_rad_s, double dt_s) const {
  PlacedReference placed;
  placed.q_RB = q_ref_RB;
  const std::int64_t half_period_ns = period_ns_ / 2;
  if (ref_ns >= now_ns - half_period_ns) return placed;  // this epoch's own (or a stamp ahead of it)
  placed.late_s = ns_to_seconds(now_ns - ref_ns);
  placed.age = ReferenceAge::kTooLate;
  if (count_ == 0 || placed.late_s > horizon_s_) return placed;
  // The buffered epoch nearest the stamp, newest first.
  for (std::size_t back = 0; back < count_; ++back) {
    const Entry& e = ring_[(head_ + ring_.size() - back) % ring_.size()];
    if (std::llabs(e.stamp_ns - ref_ns) > half_period_ns) {
      if (e.stamp_ns < ref_ns) break;  // older epochs only move further away
      continue;
    }
    const Quaternion& newest = ring_[head_].gyro_RB;
    placed.q_RB =
        propagate((q_ref_RB * (e.gyro_RB.conjugate() * newest)).normalized(), omega_BR_B_rad_s, dt_s);
    placed.age = ReferenceAge::kDelayed;
    return placed;
  }
  return placed;
}

std::optional<Quaternion> ReferenceHorizon::admit(const Epoch& epoch, const Quaternion& q_ref_RB,
                                                  const Eigen::Vector3d& omega_BR_B_rad_s, double dt_s,
                                                  Counters& counters, std::vector<FdiEvent>& events) {
  if (!epoch.reference_stamp_ns) {  // stamped at its epoch (a log's row, an in-time sample)
    late_run_ = false;
    return q_ref_RB;
  }
  const PlacedReference placed =
      place(*epoch.reference_stamp_ns, q_ref_RB, epoch.stamp_ns, omega_BR_B_rad_s, dt_s);
  if (placed.age != ReferenceAge::kTooLate) {
    if (placed.age == ReferenceAge::kDelayed) ++counters.reference_delayed;
    late_run_ = false;
    return placed.q_RB;
  }
  ++counters.reference_too_late;
  if (!late_run_) {
    FdiEvent e;
    e.stamp_ns = epoch.stamp_ns;
    e.type = EventType::kReferenceLate;
    e.statistic = placed.late_s;
    char text[160];
    std::snprintf(
        text, sizeof text,
        "attitude reference %.3f s late, beyond the fusion horizon (%.3g s) or off its epochs: left "
        "out, as is each one as late",
        placed.late_s, horizon_s_);
    e.detail = text;
    events.push_back(std::move(e));
  }
  late_run_ = true;
  return std::nullopt;
}

}  // namespace tetra::fdi::detail
