#include "tetra/player/player_link.hpp"

#include <algorithm>
#include <utility>

#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/topics.hpp"

namespace tetra::player {

namespace {
enum PlayerToken : std::intptr_t { kPlayerAttitude = 1, kPlayerMatched, kPlayerShutdown };
constexpr std::int64_t kPlayerSettle_ns = 200'000'000;   //!< [ns] discovery settling for other readers
constexpr std::int64_t kHeldGiveUp_ns = 30'000'000'000;  //!< [ns] longest a reader may hold a write back
}  // namespace

Result<std::unique_ptr<PlayerLink>> PlayerLink::open(const std::string& unit, double rate_hz,
                                                     bool with_reference, const PlayOptions& options,
                                                     dds::ShutdownSignal* shutdown, StopPoll stop) {
  auto session = dds::Session::open(options.domain, unit);
  if (!session) return session.error();
  const double wall_rate_hz = rate_hz * (options.speed > 0 ? options.speed : 1.0);
  dds::Qos gyro_qos = dds::gyro_sample_qos(std::chrono::nanoseconds(seconds_to_ns(1.0 / wall_rate_hz)));
  gyro_qos.no_autodispose();
  // Every sample kept until each reader has acknowledged it: a reader that falls behind (a recorder
  // paused, a loaded machine) holds the player back instead of losing what it had not taken.
  gyro_qos.keep_all();
  auto gyro = session->writer<tetra_GyroSample>(gyro_qos);
  if (!gyro) return gyro.error();
  auto reference = session->writer<tetra_AttitudeReference>(dds::reference_qos());
  if (!reference) return reference.error();
  dds::Qos attitude_qos;
  attitude_qos.reliable().volatile_durability().keep_last(1024);  // lockstep looks for every epoch's
  auto attitude = session->reader<tetra_Attitude>(attitude_qos);
  if (!attitude) return attitude.error();
  std::unique_ptr<PlayerLink> link(new PlayerLink(unit, std::move(session).value(), std::move(gyro).value(),
                                                  std::move(reference).value(), std::move(attitude).value()));
  link->shutdown_ = shutdown;
  link->stop_ = std::move(stop);
  if (auto s = dds::copy_bounded(link->sample_.unit, unit, "unit"); !s) return s.error();
  if (auto s = dds::copy_bounded(link->reference_msg_.unit, unit, "unit"); !s) return s.error();
  if (auto s = link->wait_for_readers(options, with_reference); !s) return s.error();
  if (auto s = link->wait_for_service(options); !s) return s.error();
  return link;
}

Status PlayerLink::wait_for_readers(const PlayOptions& options, bool with_reference) {
  if (auto s = session_.watch_data(attitude_.handle(), kPlayerAttitude); !s) return s.error();
  for (dds_entity_t w : {gyro_.handle(), reference_.handle()}) {
    if (auto s = session_.watch_statuses(w, DDS_PUBLICATION_MATCHED_STATUS, kPlayerMatched); !s)
      return s.error();
  }
  auto guard = session_.add_guard(kPlayerShutdown);
  if (!guard) return guard.error();
  if (shutdown_ != nullptr) shutdown_->set_guard((*guard)->handle());
  const std::int64_t give_up = dds::monotonic_ns() + seconds_to_ns(options.wait_timeout_s);
  for (;;) {
    std::uint32_t status = 0;
    (void)dds_take_status(gyro_.handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
    (void)dds_take_status(reference_.handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
    auto gyros = gyro_.matched_readers();
    if (!gyros) return gyros.error();
    auto references = reference_.matched_readers();
    if (!references) return references.error();
    // A log with a reference: the service's reference reader too (its first sample sets the attitude).
    const int references_needed = with_reference ? std::min(options.wait_readers, 1) : 0;
    if (static_cast<int>(*gyros) >= options.wait_readers &&
        static_cast<int>(*references) >= references_needed)
      return ok_status();
    if (stop_requested()) return failure("interrupted while waiting for readers");
    const std::int64_t now = dds::monotonic_ns();
    if (now >= give_up) {
      return failure("only " + std::to_string(*gyros) + " of " + std::to_string(options.wait_readers) +
                     " GyroSample readers appeared within " + std::to_string(options.wait_timeout_s) +
                     " s (is `tetra fusion` running on this domain? docs/troubleshooting.md)");
    }
    if (auto s = session_.wait(wait_for(give_up), triggered_); !s) return s.error();
  }
}

Status PlayerLink::wait_for_service(const PlayOptions& options) {
  if (options.wait_readers <= 0) return ok_status();
  // A volatile reader gets only what is written after IT discovered the writer: wait until the service's
  // Health says it hears a GyroSample writer (when a service of this unit answers within a second).
  auto health = session_.reader<tetra_Health>(dds::health_qos());
  if (!health) return health.error();
  auto health_data = dds::Condition::data_available(health->handle());
  if (!health_data) return health_data.error();
  auto waitset = dds::WaitSet::create(session_.participant());
  if (!waitset) return waitset.error();
  if (auto s = waitset->attach(health_data->handle(), 1); !s) return s.error();
  bool seen = false;
  bool hears = false;
  const std::int64_t first_give_up = dds::monotonic_ns() + 1'000'000'000;
  const std::int64_t hears_give_up = dds::monotonic_ns() + seconds_to_ns(options.wait_timeout_s);
  std::vector<std::intptr_t> fired;
  for (;;) {
    auto taken = health->take([&](const tetra_Health& h, const dds_sample_info_t&) {
      if (dds::from_wire(h.unit) != unit_) return;
      seen = true;
      hears = hears || h.gyro_writers > 0;
    });
    if (!taken) return taken.error();
    const std::int64_t now = dds::monotonic_ns();
    const std::int64_t limit = seen ? hears_give_up : first_give_up;
    if (hears || now >= limit || stop_requested()) break;
    if (auto s = waitset->wait(wait_for(limit), fired); !s) return s.error();
  }
  // The service's Attitude writer (lockstep waits on it), briefly; then a settling time for other readers.
  if (auto s = session_.watch_statuses(attitude_.handle(), DDS_SUBSCRIPTION_MATCHED_STATUS, kPlayerMatched);
      !s)
    return s.error();
  const std::int64_t until = dds::monotonic_ns() + (hears ? 1'000'000'000 : kPlayerSettle_ns);
  for (;;) {
    std::uint32_t status = 0;
    (void)dds_take_status(attitude_.handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
    auto matched = attitude_.matched_writers();
    if (!matched) return matched.error();
    const std::int64_t now = dds::monotonic_ns();
    if ((*matched > 0 && options.wait_readers <= 1) || now >= until || stop_requested()) return ok_status();
    if (auto s = session_.wait(wait_for(until), triggered_); !s) return s.error();
  }
}

Status PlayerLink::publish(std::int64_t stamp_ns, std::uint64_t seq, std::span<const double> raw,
                           std::span<const std::uint8_t> present,
                           const std::optional<std::array<double, 4>>& ref_wxyz, bool lockstep,
                           std::uint64_t& samples) {
  if (ref_wxyz) {
    reference_msg_.stamp_ns = stamp_ns;
    for (std::size_t i = 0; i < 4; ++i) reference_msg_.q_RB[i] = (*ref_wxyz)[i];
    if (auto s = reference_.write(reference_msg_); !s) return s.error();
  }
  std::uint32_t flags = 0;
  if (lockstep) {  // the service waits for every sample of the epoch and its reference, however late
    const auto written = std::count(present.begin(), present.end(), std::uint8_t{1});
    flags = static_cast<std::uint32_t>(written) << dds::kGyroFlagSamplesShift;
    if (ref_wxyz) flags |= dds::kGyroFlagReferenceWritten;  // no acknowledgement wait (100 ms each)
  }
  for (std::size_t g = 0; g < raw.size(); ++g) {
    if (present[g] == 0) continue;  // not delivered in the log: not on the wire either
    sample_.gyro = static_cast<std::uint16_t>(g + 1);
    sample_.seq = seq;
    sample_.stamp_ns = stamp_ns;
    sample_.raw = raw[g];
    sample_.flags = flags;
    if (auto s = write_held(); !s) return s;
    ++samples;
  }
  return ok_status();
}

Status PlayerLink::write_held() {
  auto held =
      gyro_.write_held(sample_, std::chrono::nanoseconds(kHeldGiveUp_ns), [&] { return stop_requested(); });
  if (!held) return held.error();
  using Held = dds::Writer<tetra_GyroSample>::Held;
  if (*held == Held::stopped) return failure("interrupted while a GyroSample reader held the player back");
  if (*held == Held::timed_out) {
    return failure("a GyroSample reader has acknowledged nothing for 30 s: stopped at log time " +
                   std::to_string(ns_to_seconds(sample_.stamp_ns)) + " s (every sample before it delivered)");
  }
  return ok_status();
}

Status PlayerLink::take_attitudes(std::uint64_t& count, std::int64_t& newest_stamp_ns) {
  return take_attitudes([&](const fdi::AttitudeEstimate& a) {
    ++count;
    newest_stamp_ns = std::max(newest_stamp_ns, a.stamp_ns);
  });
}

Status PlayerLink::take_attitudes(const AttitudeSink& on_attitude) {
  auto taken = attitude_.take([&](const tetra_Attitude& msg, const dds_sample_info_t& info) {
    if (dds::from_wire(msg.unit) == unit_ && attitude_writer_.accept(info.publication_handle))
      on_attitude(dds::from_wire(msg));
  });
  if (!taken) return taken.error();
  return attitude_writer_.status(unit_);
}

Result<bool> PlayerLink::wait_for_stamp(std::int64_t stamp_ns, std::int64_t timeout_ns,
                                        std::int64_t& newest_stamp_ns, const AttitudeSink& on_attitude) {
  const AttitudeSink sink = [&](const fdi::AttitudeEstimate& a) {
    newest_stamp_ns = std::max(newest_stamp_ns, a.stamp_ns);
    on_attitude(a);
  };
  if (Status s = take_attitudes(sink); !s) return s.error();
  const std::int64_t give_up = dds::monotonic_ns() + timeout_ns;
  while (newest_stamp_ns < stamp_ns && dds::monotonic_ns() < give_up && !stop_requested()) {
    if (Status s = wait_until(give_up); !s) return s.error();
    if (Status s = take_attitudes(sink); !s) return s.error();
  }
  return newest_stamp_ns >= stamp_ns;
}

Status PlayerLink::wait_until(std::int64_t until_ns) {
  const std::int64_t now = dds::monotonic_ns();
  if (now >= until_ns || stop_requested()) return ok_status();
  return session_.wait(wait_for(until_ns), triggered_);
}

std::chrono::nanoseconds PlayerLink::wait_for(std::int64_t until_ns) const {
  const std::int64_t left = std::max<std::int64_t>(0, until_ns - dds::monotonic_ns());
  return std::chrono::nanoseconds(stop_ ? std::min(left, kStopPollEvery_ns) : left);
}

void PlayerLink::wait_for_acks() {
  (void)gyro_.wait_for_acks(std::chrono::seconds(2));
}

}  // namespace tetra::player
