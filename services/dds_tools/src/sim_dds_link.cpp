#include "tetra/dds_tools/sim_dds_link.hpp"

#include <algorithm>
#include <utility>

#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/report/text.hpp"

namespace tetra::dds_tools {

using dds::monotonic_ns;
using report::fixed;

namespace {
enum LinkToken : std::intptr_t { kLinkAttitude = 1, kLinkMatched, kLinkShutdown };
constexpr std::int64_t kDiscoverySettle_ns = 200'000'000;  //!< [ns] see wait_for_service
}  // namespace

Result<std::unique_ptr<SimDdsLink>> SimDdsLink::open(const std::string& unit, double rate_hz,
                                                     const SimDdsOptions& options,
                                                     const dds::ShutdownSignal* shutdown) {
  auto session = dds::Session::open(options.domain, unit);
  if (!session) return session.error();
  // The deadline offered is 3 periods of the wall-clock rate (none when unpaced).
  const auto period = options.speed > 0
                          ? std::chrono::nanoseconds(seconds_to_ns(1.0 / (rate_hz * options.speed)))
                          : std::chrono::nanoseconds(0);
  // The reference writer first: a participant's endpoints are announced in order on one reliable
  // channel, so a service whose Health says it hears the gyro writer (wait_for_service) has discovered
  // the reference writer too, and receives the first epoch's reference (a volatile reader gets only
  // what is written after it has discovered the writer).
  auto reference_writer = session->writer<tetra_AttitudeReference>(dds::reference_qos());
  if (!reference_writer) return reference_writer.error();
  dds::Qos gyro_qos = dds::gyro_sample_qos(period);
  gyro_qos.no_autodispose();
  auto gyro_writer = session->writer<tetra_GyroSample>(gyro_qos);
  if (!gyro_writer) return gyro_writer.error();
  dds::Qos attitude_qos;
  attitude_qos.reliable().volatile_durability().keep_last(1024);  // score every epoch, not only the latest
  auto attitude_reader = session->reader<tetra_Attitude>(attitude_qos);
  if (!attitude_reader) return attitude_reader.error();
  std::unique_ptr<SimDdsLink> link(
      new SimDdsLink(unit, std::move(session).value(), std::move(gyro_writer).value(),
                     std::move(reference_writer).value(), std::move(attitude_reader).value()));
  link->shutdown_ = shutdown;
  if (auto s = dds::copy_bounded(link->sample_.unit, unit, "unit"); !s) return s.error();
  if (auto s = dds::copy_bounded(link->reference_.unit, unit, "unit"); !s) return s.error();
  if (auto s = link->wait_for_readers(options); !s) return s.error();
  if (auto s = link->wait_for_service(options); !s) return s.error();
  return link;
}

Status SimDdsLink::wait_for_readers(const SimDdsOptions& options) {
  if (auto s = session_.watch_data(attitude_reader_.handle(), kLinkAttitude); !s) return s.error();
  if (auto s = session_.watch_statuses(gyro_writer_.handle(), DDS_PUBLICATION_MATCHED_STATUS, kLinkMatched);
      !s)
    return s.error();
  if (auto s =
          session_.watch_statuses(reference_writer_.handle(), DDS_PUBLICATION_MATCHED_STATUS, kLinkMatched);
      !s)
    return s.error();
  auto guard = session_.add_guard(kLinkShutdown);
  if (!guard) return guard.error();
  if (shutdown_ != nullptr) const_cast<dds::ShutdownSignal*>(shutdown_)->set_guard((*guard)->handle());

  // Wait for the readers (the service, a recorder) so that the first samples are not lost.
  const std::int64_t give_up = monotonic_ns() + seconds_to_ns(options.wait_timeout_s);
  for (;;) {
    std::uint32_t status = 0;
    (void)dds_take_status(gyro_writer_.handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
    (void)dds_take_status(reference_writer_.handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
    auto matched = gyro_writer_.matched_readers();
    if (!matched) return matched.error();
    // The reference reader too (the service's): the first reference sample sets the filter's attitude, so
    // losing it to discovery would make the run depend on timing.
    auto references = reference_writer_.matched_readers();
    if (!references) return references.error();
    if (static_cast<int>(*matched) >= options.wait_readers &&
        static_cast<int>(*references) >= std::min(options.wait_readers, 1))
      break;
    if (stop_requested()) return failure("interrupted while waiting for readers");
    const std::int64_t now = monotonic_ns();
    if (now >= give_up) {
      return failure("only " + std::to_string(*matched) + " of " + std::to_string(options.wait_readers) +
                     " GyroSample readers appeared within " + fixed(options.wait_timeout_s, 1) + " s" +
                     incompatible_readers_note());
    }
    if (auto s = session_.wait(std::chrono::nanoseconds(give_up - now), triggered_); !s) return s.error();
  }
  return ok_status();
}

std::string SimDdsLink::incompatible_readers_note() const {
  // A reader that was discovered but refused this writer's QoS is counted on the writer's side.
  for (const auto& [writer, topic] : {std::pair{gyro_writer_.handle(), "GyroSample"},
                                      std::pair{reference_writer_.handle(), "AttitudeReference"}}) {
    dds_offered_incompatible_qos_status_t st{};
    if (dds_get_offered_incompatible_qos_status(writer, &st) != DDS_RETCODE_OK || st.total_count == 0)
      continue;
    std::string note = "; " + std::to_string(st.total_count) + " " + topic +
                       " reader(s) refused this writer's QoS: " + dds::qos_policy_name(st.last_policy_id) +
                       " (policy id " + std::to_string(st.last_policy_id) + ")";
    if (st.last_policy_id == DDS_DEADLINE_QOS_POLICY_ID) {
      note +=
          ", the reader asks for a shorter deadline than 3 periods of --rate-hz: run at the service's "
          "sample_rate_hz";
    }
    return note + " (docs/troubleshooting.md)";
  }
  return {};
}

Status SimDdsLink::wait_for_service(const SimDdsOptions& options) {
  // A volatile reader receives only what is written after IT has discovered the writer, which can
  // be a moment after the writer has discovered the reader. So wait, when a service for this unit
  // exists (its Health arrives within a second), until its Health says it hears a GyroSample writer.
  if (options.wait_readers > 0) {
    auto health_reader = session_.reader<tetra_Health>(dds::health_qos());
    if (!health_reader) return health_reader.error();
    auto health_data = dds::Condition::data_available(health_reader->handle());
    if (!health_data) return health_data.error();
    auto health_waitset = dds::WaitSet::create(session_.participant());
    if (!health_waitset) return health_waitset.error();
    if (auto s = health_waitset->attach(health_data->handle(), 1); !s) return s.error();
    bool service_seen = false;
    bool service_hears = false;
    const std::int64_t first_give_up = monotonic_ns() + 1'000'000'000;
    const std::int64_t hears_give_up = monotonic_ns() + seconds_to_ns(options.wait_timeout_s);
    std::vector<std::intptr_t> fired;
    for (;;) {
      auto taken = health_reader->take([&](const tetra_Health& h, const dds_sample_info_t&) {
        if (dds::from_wire(h.unit) != unit_) return;
        service_seen = true;
        service_hears = service_hears || h.gyro_writers > 0;
      });
      if (!taken) return taken.error();
      const std::int64_t now = monotonic_ns();
      const std::int64_t limit = service_seen ? hears_give_up : first_give_up;
      if (service_hears || now >= limit || stop_requested()) break;
      if (auto s = health_waitset->wait(std::chrono::nanoseconds(limit - now), fired); !s) return s.error();
    }
  }

  // And (briefly) for the service's Attitude writer, so that the first epochs are scored too.
  if (options.wait_readers > 0) {
    if (auto s =
            session_.watch_statuses(attitude_reader_.handle(), DDS_SUBSCRIPTION_MATCHED_STATUS, kLinkMatched);
        !s)
      return s.error();
    const std::int64_t attitude_give_up = monotonic_ns() + 1'000'000'000;
    for (;;) {
      std::uint32_t status = 0;
      (void)dds_take_status(attitude_reader_.handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
      auto matched = attitude_reader_.matched_writers();
      if (!matched) return matched.error();
      const std::int64_t now = monotonic_ns();
      if (*matched > 0 || now >= attitude_give_up || stop_requested()) break;
      if (auto s = session_.wait(std::chrono::nanoseconds(attitude_give_up - now), triggered_); !s)
        return s.error();
    }
  }

  // Other readers (a recorder) give no such sign of having discovered our writer: allow them a
  // settling time well above the 3–20 ms discovery takes on loopback, before the first sample.
  if (options.wait_readers > 1) {
    const std::int64_t settle_until = monotonic_ns() + kDiscoverySettle_ns;
    for (std::int64_t now = monotonic_ns(); now < settle_until && !stop_requested(); now = monotonic_ns()) {
      if (auto s = session_.wait(std::chrono::nanoseconds(settle_until - now), triggered_); !s)
        return s.error();
    }
  }
  return ok_status();
}

Status SimDdsLink::publish(const sim::SimEpoch& epoch, std::uint64_t k) {
  if (epoch.reference_q_RB) {
    reference_.stamp_ns = epoch.stamp_ns;
    const auto q = to_wxyz(*epoch.reference_q_RB);
    for (std::size_t i = 0; i < 4; ++i) reference_.q_RB[i] = q[i];
    if (auto s = reference_writer_.write(reference_); !s) return s.error();
  }
  for (std::size_t g = 1; g <= epoch.present.size(); ++g) {
    if (epoch.present[g - 1] == 0) continue;  // not delivered (dropout)
    sample_.gyro = static_cast<std::uint16_t>(g);
    sample_.seq = k;  // the sensor's count: a dropped sample leaves a gap
    sample_.stamp_ns = epoch.stamp_ns;
    sample_.raw = epoch.raw_V[g - 1];
    sample_.flags = epoch.reference_q_RB ? dds::kGyroFlagReferenceWritten : 0u;
    if (auto s = gyro_writer_.write(sample_); !s) return s.error();
  }
  return ok_status();
}

Status SimDdsLink::take_attitudes(const std::function<void(const fdi::AttitudeEstimate&)>& on_attitude) {
  auto taken = attitude_reader_.take([&](const tetra_Attitude& msg, const dds_sample_info_t& info) {
    if (dds::from_wire(msg.unit) == unit_ && attitude_writer_.accept(info.publication_handle))
      on_attitude(dds::from_wire(msg));
  });
  if (!taken) return taken.error();
  return attitude_writer_.status(unit_);
}

Status SimDdsLink::wait_until(std::int64_t until_ns) {
  const std::int64_t now = monotonic_ns();
  if (now >= until_ns || stop_requested()) return ok_status();
  return session_.wait(std::chrono::nanoseconds(until_ns - now), triggered_);
}

void SimDdsLink::wait_for_acks() {
  (void)gyro_writer_.wait_for_acks(std::chrono::seconds(2));
}

}  // namespace tetra::dds_tools
