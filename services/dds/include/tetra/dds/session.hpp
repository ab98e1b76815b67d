#pragma once
// One process's DDS set-up, written once for every service and tool (fusion, record, demo, sim --dds,
// monitor, command): the participant, the six topics, readers and writers of a type on its topic, and
// one waitset with the conditions it wakes on — samples arriving, communication statuses, guards, and
// SIGINT/SIGTERM through a ShutdownSignal.
//
// Declare a session before the readers and writers made from it, so that they go first: deleting the
// participant deletes every entity under it, and a reader takes its read conditions along (the session's
// later delete of one finds it gone, which is harmless).

#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <type_traits>
#include <vector>

#include "tetra.h"  // generated from idl/tetra.idl
#include "tetra/core/result.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"

namespace tetra::dds {

//! The topic of the generated type `T` among `topics`.
template <class T>
const Topic& topic_of(const Topics& topics) {
  if constexpr (std::is_same_v<T, tetra_GyroSample>) {
    return topics.gyro_sample;
  } else if constexpr (std::is_same_v<T, tetra_AttitudeReference>) {
    return topics.reference;
  } else if constexpr (std::is_same_v<T, tetra_Attitude>) {
    return topics.attitude;
  } else if constexpr (std::is_same_v<T, tetra_Health>) {
    return topics.health;
  } else if constexpr (std::is_same_v<T, tetra_FdiEvent2>) {
    return topics.event;
  } else {
    static_assert(std::is_same_v<T, tetra_Command>, "not a tetra topic type");
    return topics.command;
  }
}

class Session {
 public:
  //! Participant on `domain` serving `unit` ("": every unit; see Participant::create), its topics and
  //! an empty waitset.
  static Result<Session> open(dds_domainid_t domain, const std::string& unit = {});

  const Participant& participant() const { return participant_; }
  const Topics& topics() const { return topics_; }

  //! A reader of `T` on its topic.
  template <class T>
  Result<Reader<T>> reader(const Qos& qos) const {
    return Reader<T>::create(participant_, topic_of<T>(topics_), qos);
  }
  //! A writer of `T` on its topic.
  template <class T>
  Result<Writer<T>> writer(const Qos& qos) const {
    return Writer<T>::create(participant_, topic_of<T>(topics_), qos);
  }

  //! wait() returns `token` while `reader` holds samples.
  Status watch_data(dds_entity_t reader, std::intptr_t token);
  //! Enables the communication statuses `mask` (DDS_*_STATUS) of a reader or writer; wait() returns
  //! `token` when one of them changes (take them with dds_take_status to re-arm).
  Status watch_statuses(dds_entity_t entity, std::uint32_t mask, std::intptr_t token);
  //! A guard condition, owned by the session, that wakes wait() with `token` once triggered.
  Result<const Condition*> add_guard(std::intptr_t token);
  //! SIGINT/SIGTERM (through `shutdown`) wake wait() with `token`.
  Status watch_shutdown(ShutdownSignal& shutdown, std::intptr_t token);

  //! Blocks up to `timeout` (negative: 0); `triggered` receives the tokens (empty on timeout).
  Status wait(std::chrono::nanoseconds timeout, std::vector<std::intptr_t>& triggered) const;

 private:
  Session(Participant participant, Topics topics, WaitSet waitset)
      : participant_(std::move(participant)), topics_(std::move(topics)), waitset_(std::move(waitset)) {}

  Participant participant_;
  Topics topics_;
  WaitSet waitset_;
  std::deque<Condition> conditions_;  //!< a deque: add_guard()'s pointers stay valid
};

}  // namespace tetra::dds
