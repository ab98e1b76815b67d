#include "tetra/service/epoch_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tetra/core/units.hpp"

namespace tetra::service {

namespace {

//! Serial-number difference a − b (modulo 2^64, RFC 1982) as a signed number: wrap-around safe.
std::int64_t serial_difference(std::uint64_t a, std::uint64_t b) {
  const std::uint64_t d = a - b;
  if (d <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
    return static_cast<std::int64_t>(d);
  return -static_cast<std::int64_t>(~d) - 1;  // d − 2^64, without an out-of-range conversion
}

}  // namespace

Status validate(const AssemblerConfig& config) {
  if (config.gyro_count < 1 || config.gyro_count > 32) {
    return bad_input("assembler: gyro_count " + std::to_string(config.gyro_count) + " is outside 1..32");
  }
  if (config.nominal_period_ns <= 0 || config.nominal_period_ns > 1000 * kNanosPerSecond) {
    return bad_input("assembler: the sample period must be in (0, 1000] s");
  }
  if (config.tolerance_ns < 0 || 2 * config.tolerance_ns >= config.nominal_period_ns) {
    return bad_input("assembler: tolerance_s must be in [0, period/2)");
  }
  if (config.max_latency_ns <= 0) return bad_input("assembler: max_latency_s must be positive");
  if (config.clock_window_ns < 2 * config.nominal_period_ns || config.clock_window_ns > kStampLimit_ns) {
    return bad_input("assembler: clock_window_s must be at least 2 sample periods");
  }
  if (!(config.speed >= 0.0 && config.speed <= 1000.0))
    return bad_input("assembler: speed must be in [0, 1000]");
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
    case Verdict::kTimeOutlier:
      return "time outlier";
    case Verdict::kSeqDiscontinuity:
      return "sequence discontinuity";
  }
  return "?";
}

Result<EpochAssembler> EpochAssembler::create(const AssemblerConfig& config) {
  if (auto status = validate(config); !status) return status.error();
  return EpochAssembler(config);
}

EpochAssembler::EpochAssembler(const AssemblerConfig& config)
    : config_(config), gyros_(static_cast<std::size_t>(config.gyro_count)) {}

double EpochAssembler::lead_ns(const Clock& clock, std::int64_t stamp_ns, std::int64_t now_ns) const {
  if (!clock.ref_stamp_ns) return 0.0;
  // Stamps are within ±kStampLimit_ns: their difference does not overflow.
  return static_cast<double>(stamp_ns - *clock.ref_stamp_ns) -
         config_.speed * static_cast<double>(now_ns - clock.ref_local_ns);
}

void EpochAssembler::observe(Clock& clock, std::int64_t stamp_ns, std::int64_t now_ns) const {
  if (!clock.ref_stamp_ns || stamp_ns >= *clock.ref_stamp_ns) {
    clock.ref_stamp_ns = stamp_ns;
    clock.ref_local_ns = now_ns;
  }
}

bool EpochAssembler::on_clock(const Clock& clock, std::optional<std::int64_t> last_stamp_ns,
                              std::int64_t stamp_ns, std::int64_t now_ns) const {
  if (lead_ns(clock, stamp_ns, now_ns) > static_cast<double>(config_.clock_window_ns)) return false;
  const std::int64_t max_lag_ns = config_.clock_window_ns + kMaxLagPeriods * config_.nominal_period_ns;
  if (clock.ref_stamp_ns && stamp_ns < *clock.ref_stamp_ns - max_lag_ns) return false;
  return !last_stamp_ns || stamp_ns >= *last_stamp_ns - config_.clock_window_ns;
}

void EpochAssembler::forget_time_base() {
  for (GyroTrack& g : gyros_) g = GyroTrack{{}, {}, {}, g.absent};
  pending_.clear();
  references_.clear();
  late_references_.clear();
  crowding_ = false;
  last_emitted_ns_.reset();
  clock_ = Clock{};
  candidate_.reset();
}

bool EpochAssembler::confirm_new_clock(std::size_t index, std::int64_t stamp_ns, std::int64_t now_ns) {
  const bool agrees = candidate_ &&
                      on_clock(*candidate_, candidate_->last_stamp_ns[index], stamp_ns, now_ns) &&
                      (!candidate_->last_stamp_ns[index] || stamp_ns > *candidate_->last_stamp_ns[index]);
  if (!agrees) {
    candidate_ = Clock{};
    candidate_->last_stamp_ns.assign(gyros_.size(), std::nullopt);
    candidate_->samples.assign(gyros_.size(), 0);
  }
  Clock& candidate = *candidate_;
  observe(candidate, stamp_ns, now_ns);
  candidate.last_stamp_ns[index] = stamp_ns;
  ++candidate.samples[index];
  for (std::size_t i = 0; i < gyros_.size(); ++i) {
    if (!gyros_[i].absent && candidate.samples[i] < kRestartSamples) {
      ++counters_.time_outlier;
      return false;
    }
  }
  // Every gyro delivering agrees on the new time base and none was accepted on the old: re-anchor.
  forget_time_base();
  ++counters_.sensor_restarts;
  return true;
}

Verdict EpochAssembler::check_seq(GyroTrack& track, std::uint64_t seq, std::int64_t stamp_ns) {
  if (!track.last_seq) {
    track.last_seq = seq;
    return Verdict::kAccepted;
  }
  // A gap is credible up to 2 numbers per nominal period the stamp moved, plus the slack.
  std::uint64_t credible = kSeqSlack;
  if (track.last_stamp_ns && stamp_ns > *track.last_stamp_ns) {
    credible += 2 * static_cast<std::uint64_t>((stamp_ns - *track.last_stamp_ns) / config_.nominal_period_ns);
  }
  const std::int64_t d = serial_difference(seq, *track.last_seq);
  if (d == 0) {
    ++counters_.samples_duplicate;
    return Verdict::kDuplicate;
  }
  if (d > 0 && static_cast<std::uint64_t>(d) - 1 <= credible) {
    counters_.samples_gap += static_cast<std::uint64_t>(d) - 1;
    track.last_seq = seq;
    track.jumped_seq.reset();
    return Verdict::kAccepted;
  }
  if (d < 0 && d != std::numeric_limits<std::int64_t>::min() && static_cast<std::uint64_t>(-d) <= credible) {
    ++counters_.samples_out_of_order;
    return Verdict::kOutOfOrder;
  }
  // A jump no elapsed time explains: the numbering restarted (then the next sample continues from
  // here) or this number is corrupt (then the next continues from the old one).
  if (track.jumped_seq) {
    const std::int64_t from_jump = serial_difference(seq, *track.jumped_seq);
    if (from_jump > 0 && static_cast<std::uint64_t>(from_jump) <= kSeqSlack) {
      track.last_seq = seq;
      track.jumped_seq.reset();
      return Verdict::kAccepted;
    }
  }
  track.jumped_seq = seq;
  ++counters_.seq_discontinuity;
  return Verdict::kSeqDiscontinuity;
}

Verdict EpochAssembler::add_sample(int gyro_id, std::uint64_t seq, std::int64_t stamp_ns, double raw,
                                   std::int64_t now_ns, bool reference_written, int promised) {
  if (gyro_id < 1 || gyro_id > config_.gyro_count) {
    ++counters_.samples_unknown_gyro;
    return Verdict::kUnknownGyro;
  }
  if (stamp_ns > kStampLimit_ns || stamp_ns < -kStampLimit_ns) {
    ++counters_.time_outlier;
    return Verdict::kTimeOutlier;
  }
  const auto index = static_cast<std::size_t>(gyro_id - 1);
  const bool all_absent =
      std::all_of(gyros_.begin(), gyros_.end(), [](const GyroTrack& g) { return g.absent; });
  const GyroTrack& seen = gyros_[index];
  const bool went_back = (seen.last_seq && serial_difference(seq, *seen.last_seq) <= 0) ||
                         (seen.last_stamp_ns && stamp_ns <= *seen.last_stamp_ns);
  if (all_absent && went_back) {
    // The unit went silent and came back with a new time base: start afresh.
    forget_time_base();
    ++counters_.sensor_restarts;
  }
  if (all_absent) {
    // The unit resumes: wait for all of its gyros again (those really gone are marked absent again
    // by their deadline), so a pause of the whole stream does not split its next epochs.
    for (GyroTrack& g : gyros_) g.absent = false;
  }
  GyroTrack& track = gyros_[index];
  if (!on_clock(clock_, track.last_stamp_ns, stamp_ns, now_ns) &&
      !confirm_new_clock(index, stamp_ns, now_ns)) {
    return Verdict::kTimeOutlier;
  }
  if (const Verdict verdict = check_seq(track, seq, stamp_ns); verdict != Verdict::kAccepted) return verdict;
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
  observe(clock_, stamp_ns, now_ns);
  candidate_.reset();  // a sample on the unit's clock: the outliers were not a new time base

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
  it->awaits_reference = it->awaits_reference || reference_written;
  it->promised = std::max(it->promised, std::min(promised, config_.gyro_count));
  return Verdict::kAccepted;
}

std::optional<CrowdedOutReference> EpochAssembler::add_reference(std::int64_t stamp_ns,
                                                                 const Quaternion& q_RB) {
  const auto by_stamp = [](std::int64_t t, const auto& r) { return t < r.first; };
  if (!last_emitted_ns_ || stamp_ns > *last_emitted_ns_ + config_.tolerance_ns) {
    references_.insert(std::upper_bound(references_.begin(), references_.end(), stamp_ns, by_stamp),
                       {stamp_ns, q_RB});
    return std::nullopt;
  }
  // Its epoch was fused: it goes with one of the next at its own time (the pipeline's fusion horizon).
  late_references_.insert(
      std::upper_bound(late_references_.begin(), late_references_.end(), stamp_ns, by_stamp),
      {stamp_ns, q_RB});
  if (late_references_.size() <= kMaxLateReferences) return std::nullopt;
  const CrowdedOutReference crowded{late_references_.front().first,
                                    ns_to_seconds(*last_emitted_ns_ - late_references_.front().first)};
  late_references_.pop_front();  // the oldest waiting gives way
  ++counters_.references_crowded_out;
  const bool first_of_run = !crowding_;
  crowding_ = true;
  return first_of_run ? std::optional<CrowdedOutReference>(crowded) : std::nullopt;
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

namespace {
bool all_promised_in(const std::vector<std::uint8_t>& present, int promised) {
  return promised > 0 && std::count(present.begin(), present.end(), std::uint8_t{1}) >= promised;
}
}  // namespace

bool EpochAssembler::promise_kept(const Pending& epoch) const {
  if (all_promised_in(epoch.present, epoch.promised)) return true;
  for (std::size_t i = 0; i < gyros_.size(); ++i) {
    const GyroTrack& track = gyros_[i];
    if (epoch.present[i] == 0 && track.last_stamp_ns &&
        *track.last_stamp_ns > epoch.stamp_ns + config_.tolerance_ns)
      return true;  // a gyro missing from it has moved on: what it was promised is lost
  }
  return false;
}

bool EpochAssembler::reference_in(const Pending& epoch) const {
  return std::any_of(references_.begin(), references_.end(), [&](const auto& r) {
    return std::llabs(r.first - epoch.stamp_ns) <= config_.tolerance_ns;
  });
}

bool EpochAssembler::moved_past(const Pending& epoch) const {
  return std::any_of(gyros_.begin(), gyros_.end(), [&](const GyroTrack& track) {
    return track.last_stamp_ns && *track.last_stamp_ns > epoch.stamp_ns + config_.tolerance_ns;
  });
}

bool EpochAssembler::ready(const Pending& epoch, std::int64_t now_ns) const {
  if (epoch.promised > 0 && !promise_kept(epoch)) return false;  // however late: no max_latency_ns
  // Its reference too, promised by the same sender (lockstep: written first, never acknowledged).
  if (epoch.promised > 0 && epoch.awaits_reference && !reference_in(epoch) && !moved_past(epoch))
    return false;
  if (now_ns - epoch.opened_local_ns >= config_.max_latency_ns) return true;
  // Every sample the sender wrote is in: the gyros it did not write are not waited for.
  const bool complete = all_promised_in(epoch.present, epoch.promised);
  for (std::size_t i = 0; i < gyros_.size() && !complete; ++i) {
    const GyroTrack& track = gyros_[i];
    const bool moved_past =
        track.last_stamp_ns && *track.last_stamp_ns > epoch.stamp_ns + config_.tolerance_ns;
    if (epoch.present[i] == 0 && !track.absent && !moved_past) return false;
  }
  return !epoch.awaits_reference || reference_in(epoch);
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
  } else if (epoch.awaits_reference) {
    ++counters_.references_late;  // announced, and not in within max_latency_ns: the epoch goes without
  }
  if (!result.reference_q_RB && !late_references_.empty()) {  // an epoch's own reference goes first
    result.reference_q_RB = late_references_.front().second;
    result.reference_stamp_ns = late_references_.front().first;
    late_references_.pop_front();
  }
  crowding_ = crowding_ && !late_references_.empty();  // a run of crowded-out ones ends when all went on
  const auto delivered = std::count(result.present.begin(), result.present.end(), std::uint8_t{1});
  if (epoch.promised > delivered)
    counters_.samples_promised_lost += static_cast<std::uint64_t>(epoch.promised - delivered);
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
  const Pending& front = pending_.front();
  if (front.promised > 0 && !promise_kept(front)) return std::nullopt;  // a sample's arrival decides
  return front.opened_local_ns + config_.max_latency_ns;
}

}  // namespace tetra::service
