#include "tetra/service/duplicate_watch.hpp"

#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/topics.hpp"

namespace tetra::service {

Result<DuplicateWatch> DuplicateWatch::create(const dds::Session& session, std::string unit, int domain) {
  auto reader = session.reader<tetra_Health>(dds::health_qos());
  if (!reader) return reader.error();
  return DuplicateWatch(std::move(reader).value(), std::move(unit), domain);
}

Status DuplicateWatch::set_own_writer(dds_entity_t own_health_writer) {
  if (const dds_return_t rc = dds_get_instance_handle(own_health_writer, &own_writer_); rc < 0)
    return failure("fusion: the Health writer's handle: " + std::string(dds_strretcode(rc)));
  return ok_status();
}

Status DuplicateWatch::check() const {
  std::uint64_t other_epochs = 0;
  bool heard = false;
  auto taken = reader_.take([&](const tetra_Health& h, const dds_sample_info_t& info) {
    if (info.publication_handle == own_writer_ || dds::from_wire(h.unit) != unit_) return;
    heard = true;
    other_epochs = h.counters.epochs_accepted;
  });
  if (!taken) return taken.error();
  if (!heard) return ok_status();
  return failure("another fusion service for unit '" + unit_ + "' is running on domain " +
                 std::to_string(domain_) + " (its Health heard, " + std::to_string(other_epochs) +
                 " epochs fused): two services of one unit would publish two Attitude, Health and FdiEvent "
                 "streams that consumers mix; stop one of them, or give this one its own unit (docs/dds.md)");
}

Status DuplicateWatch::probe(const dds::Participant& participant, std::chrono::nanoseconds probe,
                             const std::function<bool()>& stop) const {
  auto data = dds::Condition::data_available(reader_.handle());
  if (!data) return data.error();
  auto waitset = dds::WaitSet::create(participant);
  if (!waitset) return waitset.error();
  if (auto s = waitset->attach(data->handle(), 1); !s) return s;
  std::vector<std::intptr_t> fired;
  const std::int64_t give_up = dds::monotonic_ns() + probe.count();
  for (std::int64_t now = dds::monotonic_ns(); now < give_up && !stop(); now = dds::monotonic_ns()) {
    if (auto s = waitset->wait(std::chrono::nanoseconds(give_up - now), fired); !s) return s;
    if (auto s = check(); !s) return s;
  }
  return check();
}

}  // namespace tetra::service
