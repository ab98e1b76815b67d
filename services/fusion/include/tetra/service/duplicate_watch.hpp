#pragma once
// One service per unit on a domain: a second `tetra fusion` for the same unit would publish a second
// Attitude, Health and FdiEvent stream for it, and a consumer (a lockstep simulation, a campaign, the
// ground) would mix the two without noticing. The watch reads the unit's Health (transient-local: a
// running service's last Health reaches a newcomer as soon as the two have discovered each other) and
// reports any written by another writer than the service's own.
//
//   probe()  before the service writes anything: the newcomer refuses to start (the service running
//            is not disturbed);
//   check()  while serving (two that started together, or a discovery slower than the probe): both
//            see the other's Health and stop with the error.

#include <chrono>
#include <functional>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/session.hpp"

namespace tetra::service {

class DuplicateWatch {
 public:
  //! [ns] how long a newcomer listens for another service's Health before it starts: discovery takes
  //! 3–20 ms on loopback; check() catches one found later.
  static constexpr std::chrono::milliseconds kProbe{500};

  //! A Health reader on `session` for `unit`. Create it, and probe, before the service's own readers and
  //! writers: a newcomer that refuses has then matched nobody.
  static Result<DuplicateWatch> create(const dds::Session& session, std::string unit, int domain);
  //! The service's own Health writer, once created: its samples are not a duplicate.
  Status set_own_writer(dds_entity_t own_health_writer);
  //! Waits up to `probe` for another writer's Health of the unit (`stop` ends the wait early), on a
  //! waitset of its own on `participant` (the one the reader was created on).
  Status probe(const dds::Participant& participant, std::chrono::nanoseconds probe,
               const std::function<bool()>& stop) const;
  //! Takes the Health received so far: an error naming the unit when another writer's is among it.
  Status check() const;
  dds_entity_t reader_handle() const { return reader_.handle(); }

 private:
  DuplicateWatch(dds::Reader<tetra_Health> reader, std::string unit, int domain)
      : reader_(std::move(reader)), unit_(std::move(unit)), domain_(domain) {}

  dds::Reader<tetra_Health> reader_;
  std::string unit_;
  int domain_;
  dds_instance_handle_t own_writer_ = 0;  //!< 0: none yet
};

}  // namespace tetra::service
