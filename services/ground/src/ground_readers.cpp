#include "tetra/ground/ground_readers.hpp"

namespace tetra::ground {

namespace {

using dds::assign;
constexpr int kAttitudeDepth = 64;  //!< samples per unit: 0.64 s of a 100 Hz service

}  // namespace

Result<GroundReaders> GroundReaders::open(dds_domainid_t domain, const std::string& unit,
                                          dds::ShutdownSignal& shutdown) {
  GroundReaders r;
  if (auto s = assign(r.session_, dds::Session::open(domain, unit)); !s) return s.error();
  dds::Session& session = *r.session_;
  if (auto s = assign(r.health_, session.reader<tetra_Health>(dds::health_qos())); !s) return s.error();
  if (auto s = assign(r.event_, session.reader<tetra_FdiEvent2>(dds::event_qos())); !s) return s.error();
  // A deeper history than the writer's keep-last 1: a busy ground thread still sees every epoch, so the
  // attitude it keeps is exactly one per attitude period (docs/ground.md).
  auto attitude_qos = dds::attitude_qos();
  attitude_qos.keep_last(kAttitudeDepth);
  if (auto s = assign(r.attitude_, session.reader<tetra_Attitude>(attitude_qos)); !s) return s.error();
  if (auto s = assign(r.command_, session.writer<tetra_Command>(dds::command_qos())); !s) return s.error();
  for (auto [reader, token] :
       {std::pair{r.health_->handle(), kHealthToken}, std::pair{r.event_->handle(), kEventToken},
        std::pair{r.attitude_->handle(), kAttitudeToken}}) {
    if (auto s = session.watch_data(reader, token); !s) return s.error();
  }
  // Matched-writer changes wake the waitset too (a monitor --once counts the services it hears).
  if (auto s = session.watch_statuses(r.health_->handle(), DDS_SUBSCRIPTION_MATCHED_STATUS, kHealthToken); !s)
    return s.error();
  if (auto s = session.watch_shutdown(shutdown, kShutdownToken); !s) return s.error();
  return r;
}

Status GroundReaders::take_health(const std::function<void(dds::HealthView&&, std::int64_t)>& on_health,
                                  const std::function<void(const std::string&)>& on_writer_lost) const {
  std::uint32_t status = 0;
  (void)dds_take_status(health_->handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
  auto taken = health_->take(
      [&](const tetra_Health& msg, const dds_sample_info_t& info) {
        on_health(dds::from_wire(msg), info.source_timestamp);
      },
      [&](const dds_sample_info_t& info) {
        if (info.instance_state == DDS_IST_ALIVE) return;
        tetra_Health key{};
        if (health_->instance_key(info.instance_handle, key)) on_writer_lost(dds::from_wire(key.unit));
        dds_sample_free(&key, &tetra_Health_desc, DDS_FREE_CONTENTS);
      });
  if (!taken) return taken.error();
  return ok_status();
}

Status GroundReaders::take_events(const std::function<void(dds::EventView&&, std::int64_t)>& on_event) const {
  auto taken = event_->take([&](const tetra_FdiEvent2& msg, const dds_sample_info_t& info) {
    on_event(dds::from_wire(msg), info.source_timestamp);
  });
  if (!taken) return taken.error();
  return ok_status();
}

Status GroundReaders::take_attitudes(
    const std::function<void(const std::string&, fdi::AttitudeEstimate&&, std::int64_t)>& on_attitude) const {
  auto taken = attitude_->take([&](const tetra_Attitude& msg, const dds_sample_info_t& info) {
    on_attitude(dds::from_wire(msg.unit), dds::from_wire(msg), info.source_timestamp);
  });
  if (!taken) return taken.error();
  return ok_status();
}

Status GroundReaders::wait(std::chrono::nanoseconds timeout, std::vector<std::intptr_t>& triggered) const {
  return session_->wait(timeout, triggered);
}

}  // namespace tetra::ground
