#include "tetra/service/epoch_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tetra::service {

Status validate(const AssemblerConfig& config) {
  if (config.gyro_count < 1 || config.gyro_count > 32) {
    return bad_input("assembler: gyro_count " + std::to_string(config.gyro_count) + " is outside 1..32");
  }
  if (config.nominal_period_ns <= 0) return bad_input("assembler: sample period must be positive");
  if (config.tolerance_ns < 0 || 2 * config.tolerance_ns >= config.nominal_period_ns) {
    return bad_input("assembler: tolerance_s must be in [0, period/2)");
  }
  if (config.max_latency_ns <= 0) return bad_input("assembler: max_latency_s must be positive");
  return ok_status();
}

const char* to_string(Verdict verdict) {
  switch (verdict) {
    case Verdict::kAccepted:
      return "accepted";
    case Verdict::kDuplicate:
      return "duplicate";
    case Verdict::kOutOfOrder:
      return "out of order";
    case Verdict::kLate:
      return "late";
    case Verdict::kUnknownGyro:
      return "unknown gyro";
  }
  return "?";
}

Result<EpochAssembler> EpochAssembler::create(const AssemblerConfig& config) {
  if (auto status = validate(config); !status) return status.error();
  return EpochAssembler(config);
}

EpochAssembler::EpochAssembler(const AssemblerConfig& config)
    : config_(config), gyros_(static_cast<std::size_t>(config.gyro_count)) {}

Verdict EpochAssembler::add_sample(int gyro_id, std::uint64_t seq, std::int64_t stamp_ns, double raw,
                                   std::int64_t now_ns) {
  if (gyro_id < 1 || gyro_id > config_.gyro_count) {
    ++counters_.samples_unknown_gyro;
    return Verdict::kUnknownGyro;
  }
  const auto index = static_cast<std::size_t>(gyro_id - 1);
  const bool all_absent =
      std::all_of(gyros_.begin(), gyros_.end(), [](const GyroTrack& g) { return g.absent; });
  const GyroTrack& seen = gyros_[index];
  const bool went_back =
      (seen.last_seq && seq <= *seen.last_seq) || (seen.last_stamp_ns && stamp_ns <= *seen.last_stamp_ns);
  if (all_absent && went_back) {
    // The unit went silent and came back with a new time base: start afresh.
    for (GyroTrack& g : gyros_) g = GyroTrack{};
    pending_.clear();
    references_.clear();
    last_emitted_ns_.reset();
    ++counters_.sensor_restarts;
  }
  if (all_absent) {
    // The unit resumes: wait for all of its gyros again (those really gone are marked absent again
    // by their deadline), so a pause of the whole stream does not split its next epochs.
    for (GyroTrack& g : gyros_) g.absent = false;
  }
  GyroTrack& track = gyros_[index];
  if (track.last_seq) {
    if (seq == *track.last_seq) {
      ++counters_.samples_duplicate;
      return Verdict::kDuplicate;
    }
    if (seq < *track.last_seq) {
      ++counters_.samples_out_of_order;
      return Verdict::kOutOfOrder;
    }
    counters_.samples_gap += seq - *track.last_seq - 1;
  }
  track.last_seq = seq;
  if (track.last_stamp_ns && stamp_ns <= *track.last_stamp_ns) {
    ++counters_.samples_out_of_order;
    return Verdict::kOutOfOrder;
  }
  track.absent = false;
  if (last_emitted_ns_ && stamp_ns <= *last_emitted_ns_ + config_.tolerance_ns) {
    ++counters_.samples_late;
    return Verdict::kLate;
  }
  track.last_stamp_ns = stamp_ns;

  // Join the open epoch this stamp belongs to, or open a new one in stamp order.
  auto it = std::find_if(pending_.begin(), pending_.end(), [&](const Pending& p) {
    return std::llabs(p.stamp_ns - stamp_ns) <= config_.tolerance_ns && p.present[index] == 0;
  });
  if (it == pending_.end()) {
    Pending epoch;
    epoch.stamp_ns = stamp_ns;
    epoch.opened_local_ns = now_ns;
    epoch.raw.assign(static_cast<std::size_t>(config_.gyro_count), std::numeric_limits<double>::quiet_NaN());
    epoch.present.assign(static_cast<std::size_t>(config_.gyro_count), 0);
    auto pos = std::upper_bound(pending_.begin(), pending_.end(), stamp_ns,
                                [](std::int64_t t, const Pending& p) { return t < p.stamp_ns; });
    it = pending_.insert(pos, std::move(epoch));
  }
  it->raw[index] = raw;
  it->present[index] = 1;
  return Verdict::kAccepted;
}

void EpochAssembler::add_reference(std::int64_t stamp_ns, const Quaternion& q_RB) {
  if (last_emitted_ns_ && stamp_ns <= *last_emitted_ns_ + config_.tolerance_ns) {
    ++counters_.references_late;
    return;
  }
  auto pos = std::upper_bound(references_.begin(), references_.end(), stamp_ns,
                              [](std::int64_t t, const auto& r) { return t < r.first; });
  references_.insert(pos, {stamp_ns, q_RB});
}

void EpochAssembler::mark_absent(int gyro_id, AbsentReason reason) {
  if (gyro_id < 1 || gyro_id > config_.gyro_count) return;
  GyroTrack& track = gyros_[static_cast<std::size_t>(gyro_id - 1)];
  if (track.absent) return;
  track.absent = true;
  ++(reason == AbsentReason::kDeadline ? counters_.deadlines_missed : counters_.liveliness_lost);
}

bool EpochAssembler::all_absent() const {
  return std::all_of(gyros_.begin(), gyros_.end(), [](const GyroTrack& g) { return g.absent; });
}

bool EpochAssembler::absent(int gyro_id) const {
  return gyro_id >= 1 && gyro_id <= config_.gyro_count &&
         gyros_[static_cast<std::size_t>(gyro_id - 1)].absent;
}

bool EpochAssembler::ready(const Pending& epoch, std::int64_t now_ns) const {
  if (now_ns - epoch.opened_local_ns >= config_.max_latency_ns) return true;
  for (std::size_t i = 0; i < gyros_.size(); ++i) {
    const GyroTrack& track = gyros_[i];
    const bool moved_past =
        track.last_stamp_ns && *track.last_stamp_ns > epoch.stamp_ns + config_.tolerance_ns;
    if (epoch.present[i] == 0 && !track.absent && !moved_past) return false;
  }
  return true;
}

void EpochAssembler::emit(Pending& epoch, std::vector<fdi::Epoch>& out) {
  fdi::Epoch result;
  result.stamp_ns = epoch.stamp_ns;
  result.raw = std::move(epoch.raw);
  result.present = std::move(epoch.present);
  while (!references_.empty() && references_.front().first < epoch.stamp_ns - config_.tolerance_ns) {
    references_.pop_front();  // a reference without an epoch: nothing to attach it to
  }
  if (!references_.empty() && references_.front().first <= epoch.stamp_ns + config_.tolerance_ns) {
    result.reference_q_RB = references_.front().second;
    references_.pop_front();
  }
  last_emitted_ns_ = epoch.stamp_ns;
  ++counters_.epochs_emitted;
  out.push_back(std::move(result));
}

void EpochAssembler::poll(std::int64_t now_ns, std::vector<fdi::Epoch>& out) {
  while (!pending_.empty() && ready(pending_.front(), now_ns)) {
    emit(pending_.front(), out);
    pending_.pop_front();
  }
}

std::optional<std::int64_t> EpochAssembler::next_due_ns() const {
  if (pending_.empty()) return std::nullopt;
  return pending_.front().opened_local_ns + config_.max_latency_ns;
}

}  // namespace tetra::service
