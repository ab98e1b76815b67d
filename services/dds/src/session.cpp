#include "tetra/dds/session.hpp"

namespace tetra::dds {

Result<Session> Session::open(dds_domainid_t domain, const std::string& unit) {
  auto participant = Participant::create(domain, unit);
  if (!participant) return participant.error();
  auto topics = Topics::create(*participant);
  if (!topics) return topics.error();
  auto waitset = WaitSet::create(*participant);
  if (!waitset) return waitset.error();
  return Session(std::move(participant).value(), std::move(topics).value(), std::move(waitset).value());
}

Status Session::watch_data(dds_entity_t reader, std::intptr_t token) {
  auto condition = Condition::data_available(reader);
  if (!condition) return condition.error();
  if (auto s = waitset_.attach(condition->handle(), token); !s) return s;
  conditions_.push_back(std::move(condition).value());
  return ok_status();
}

Status Session::watch_statuses(dds_entity_t entity, std::uint32_t mask, std::intptr_t token) {
  const dds_return_t rc = dds_set_status_mask(entity, mask);
  if (rc < 0) return dds_error("status mask", rc);
  return waitset_.attach(entity, token);
}

Result<const Condition*> Session::add_guard(std::intptr_t token) {
  auto guard = Condition::guard(participant_);
  if (!guard) return guard.error();
  if (auto s = waitset_.attach(guard->handle(), token); !s) return s.error();
  conditions_.push_back(std::move(guard).value());
  return &conditions_.back();
}

Status Session::watch_shutdown(ShutdownSignal& shutdown, std::intptr_t token) {
  auto guard = add_guard(token);
  if (!guard) return guard.error();
  shutdown.set_guard((*guard)->handle());
  return ok_status();
}

Status Session::wait(std::chrono::nanoseconds timeout, std::vector<std::intptr_t>& triggered) const {
  return waitset_.wait(timeout, triggered);
}

}  // namespace tetra::dds
