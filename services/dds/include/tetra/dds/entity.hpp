#pragma once
// A small RAII layer over the Cyclone DDS C API (Debian's 0.10.2 has no C++ binding).
//
// * Every entity is owned by exactly one move-only object and deleted with dds_delete().
// * Every return code is checked; failures become tetra::Error values whose message carries
//   dds_strretcode() and what was being done ("create reader GyroSample: Precondition not met").
// * Readers hand samples to a callback on loaned memory (valid only inside the callback), so
//   strings and sequences of the generated C types never need copying or freeing here.
// This is the only header of tetra that includes dds/dds.h besides the services' own sources.

#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/service_types/security_profile.hpp"

namespace tetra::dds {

//! "what: dds_strretcode(rc)" as a failure.
Error dds_error(const std::string& what, dds_return_t rc);

//! The CDR encoding a writer sends (DDS-XTypes data representation). Every tetra type is @final, so
//! either works; a writer offers exactly one, and a reader matches a writer only if it accepts that one
//! (docs/dds.md, "Data representation"). tetra's readers accept both.
enum class DataRepresentation { kXcdr1, kXcdr2 };

//! The representation of every writer this process creates from now on (default XCDR1, which every
//! DDS-XTypes reader accepts by default), unless the writer's QoS names its own.
void set_data_representation(DataRepresentation representation);
DataRepresentation data_representation();

//! DDS Security for every participant this process creates from now on; nullopt (the default): none.
//! The profile's documents become the participant's dds.sec.* QoS properties (docs/reliability.md).
void set_security_profile(std::optional<service::SecurityProfile> profile);

//! Owns one dds_entity_t (participant, topic, reader, writer, condition, waitset).
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  ~Entity() { reset(); }

  dds_entity_t handle() const { return handle_; }
  bool valid() const { return handle_ > 0; }
  void reset();

 private:
  dds_entity_t handle_ = 0;
};

//! A QoS object built fluently: Qos().reliable().keep_last(64).deadline(...).
class Qos {
 public:
  Qos();
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  Qos(Qos&& other) noexcept : qos_(std::exchange(other.qos_, nullptr)) {}
  ~Qos();

  Qos& reliable(std::chrono::nanoseconds max_blocking = std::chrono::milliseconds(100));
  Qos& best_effort();
  Qos& keep_last(int depth);
  Qos& keep_all();
  Qos& volatile_durability();
  //! Transient-local durability; late joiners receive up to `depth` samples per instance
  //! (sized by DURABILITY_SERVICE, not HISTORY — see docs/dds.md).
  Qos& transient_local(int depth);
  Qos& deadline(std::chrono::nanoseconds period);
  Qos& automatic_liveliness(std::chrono::nanoseconds lease);
  //! Keep instances when a writer is deleted (no dispose), so readers see "no writers", not "disposed".
  Qos& no_autodispose();
  Qos& partition(const std::string& name);
  //! A writer's one representation, or the list a reader accepts.
  Qos& data_representation(DataRepresentation representation);
  Qos& accept_xcdr1_and_xcdr2();
  bool has_data_representation() const;
  Qos copy() const;

  const dds_qos_t* get() const { return qos_; }
  dds_qos_t* mutable_qos() { return qos_; }

 private:
  dds_qos_t* qos_ = nullptr;
};

//! The DDS partition of a secured participant serving `unit` ("": every unit, a pattern): permissions
//! grant per topic and partition, so one partition per unit lets them grant per unit.
std::string unit_partition(const std::string& unit);

//! Domain participant. `domain` DDS_DOMAIN_DEFAULT takes the id of the configuration. `unit` names the
//! unit it serves ("": every unit). With a security profile (set_security_profile) its readers and
//! writers are created in unit_partition(unit); without one, in the default partition (docs/interfaces.md
//! §4).
class Participant {
 public:
  static Result<Participant> create(dds_domainid_t domain, const std::string& unit = {});
  dds_entity_t handle() const { return entity_.handle(); }
  //! The partition of its readers and writers ("": the default partition).
  const std::string& partition() const { return partition_; }
  //! `qos` in this participant's partition, for a reader or writer.
  Qos endpoint_qos(const Qos& qos) const;
  //! endpoint_qos() with the process's data representation (set_data_representation) unless `qos` has one.
  Qos writer_qos(const Qos& qos) const;
  //! endpoint_qos() accepting XCDR1 and XCDR2 unless `qos` restricts it.
  Qos reader_qos(const Qos& qos) const;

 private:
  Participant(Entity entity, std::string partition)
      : entity_(std::move(entity)), partition_(std::move(partition)) {}
  Entity entity_;
  std::string partition_;
};

//! A topic of the generated C type described by `descriptor`.
class Topic {
 public:
  static Result<Topic> create(const Participant& participant, const dds_topic_descriptor_t* descriptor,
                              const std::string& name, const Qos& qos);
  dds_entity_t handle() const { return entity_.handle(); }
  const std::string& name() const { return name_; }

 private:
  Topic(Entity entity, std::string name) : entity_(std::move(entity)), name_(std::move(name)) {}
  Entity entity_;
  std::string name_;
};

//! Writer of samples of type `T` (a generated C struct).
template <class T>
class Writer {
 public:
  static Result<Writer> create(const Participant& participant, const Topic& topic, const Qos& qos) {
    const Qos endpoint = participant.writer_qos(qos);
    const dds_entity_t handle =
        dds_create_writer(participant.handle(), topic.handle(), endpoint.get(), nullptr);
    if (handle < 0) return dds_error("create writer " + topic.name(), handle);
    return Writer(Entity(handle), topic.name());
  }
  Status write(const T& sample) const {
    const dds_return_t rc = dds_write(entity_.handle(), &sample);
    if (rc < 0) return dds_error("write " + name_, rc);
    return ok_status();
  }
  //! As write(), but a KEEP_ALL writer held back past max_blocking_time by a reader that has not
  //! acknowledged what it has (a slow or stopped reader) answers false instead of an error: the caller
  //! writes again, nothing is dropped.
  Result<bool> write_unless_held(const T& sample) const {
    const dds_return_t rc = dds_write(entity_.handle(), &sample);
    if (rc == DDS_RETCODE_TIMEOUT) return false;
    if (rc < 0) return dds_error("write " + name_, rc);
    return true;
  }
  //! How write_held ended.
  enum class Held { written, stopped, timed_out };
  //! write_unless_held again and again while a reader holds the write back: until it is written,
  //! `stop()` is true, or `limit` has passed with the reader acknowledging nothing. Nothing is dropped
  //! either way (a writer that keeps every sample until acknowledged, sized to any burst).
  template <class Stop>
  Result<Held> write_held(const T& sample, std::chrono::nanoseconds limit, Stop&& stop) const {
    const auto give_up = std::chrono::steady_clock::now() + limit;
    for (;;) {
      auto written = write_unless_held(sample);
      if (!written) return written.error();
      if (*written) return Held::written;
      if (stop()) return Held::stopped;
      if (std::chrono::steady_clock::now() >= give_up) return Held::timed_out;
    }
  }
  //! Unregisters the instance of `sample`'s key (readers see "no writers" for it).
  Status unregister(const T& sample) const {
    const dds_return_t rc = dds_unregister_instance(entity_.handle(), &sample);
    if (rc < 0) return dds_error("unregister " + name_, rc);
    return ok_status();
  }
  //! Number of matched readers now.
  Result<std::uint32_t> matched_readers() const {
    dds_publication_matched_status_t status{};
    const dds_return_t rc = dds_get_publication_matched_status(entity_.handle(), &status);
    if (rc < 0) return dds_error("publication matched status " + name_, rc);
    return status.current_count;
  }
  //! Blocks until every matched reliable reader acknowledged what was written, or the timeout.
  Status wait_for_acks(std::chrono::nanoseconds timeout) const {
    const dds_return_t rc = dds_wait_for_acks(entity_.handle(), timeout.count());
    if (rc < 0) return dds_error("wait for acknowledgements " + name_, rc);
    return ok_status();
  }
  dds_entity_t handle() const { return entity_.handle(); }

 private:
  Writer(Entity entity, std::string name) : entity_(std::move(entity)), name_(std::move(name)) {}
  Entity entity_;
  std::string name_;
};

//! Reader of samples of type `T` (a generated C struct).
template <class T>
class Reader {
 public:
  static Result<Reader> create(const Participant& participant, const Topic& topic, const Qos& qos) {
    const Qos endpoint = participant.reader_qos(qos);
    const dds_entity_t handle =
        dds_create_reader(participant.handle(), topic.handle(), endpoint.get(), nullptr);
    if (handle < 0) return dds_error("create reader " + topic.name(), handle);
    return Reader(Entity(handle), topic.name());
  }

  //! Takes every available sample and calls `on_sample(const T&, const dds_sample_info_t&)` for
  //! each one with valid data, oldest first per instance, and `on_state(const dds_sample_info_t&)`
  //! (if given) for invalid samples (dispose / unregister notifications). Returns the number taken.
  template <class OnSample>
  Result<int> take(OnSample&& on_sample) const {
    return take(std::forward<OnSample>(on_sample), [](const dds_sample_info_t&) {});
  }
  template <class OnSample, class OnState>
  Result<int> take(OnSample&& on_sample, OnState&& on_state) const {
    constexpr int kBatch = 64;
    int total = 0;
    for (;;) {
      void* samples[kBatch] = {nullptr};
      dds_sample_info_t infos[kBatch];
      const dds_return_t n = dds_take(entity_.handle(), samples, infos, kBatch, kBatch);
      if (n < 0) return dds_error("take " + name_, n);
      for (int i = 0; i < n; ++i) {
        if (infos[i].valid_data) {
          on_sample(*static_cast<const T*>(samples[i]), infos[i]);
        } else {
          on_state(infos[i]);
        }
      }
      if (n > 0) (void)dds_return_loan(entity_.handle(), samples, n);
      total += n;
      if (n < kBatch) return total;
    }
  }
  //! Key fields of an instance (e.g. from a deadline-missed status), as a full sample with only the
  //! key filled. Strings inside are owned by `out`: call free_contents() afterwards.
  Status instance_key(dds_instance_handle_t instance, T& out) const {
    const dds_return_t rc = dds_instance_get_key(entity_.handle(), instance, &out);
    if (rc < 0) return dds_error("instance key " + name_, rc);
    return ok_status();
  }
  //! Samples lost on the way to this reader so far (a writer dropped them from its history before this
  //! reader had them: it fell behind), and samples rejected by its history.
  Result<std::uint64_t> samples_lost() const {
    dds_sample_lost_status_t lost{};
    dds_return_t rc = dds_get_sample_lost_status(entity_.handle(), &lost);
    if (rc < 0) return dds_error("sample lost status " + name_, rc);
    dds_sample_rejected_status_t rejected{};
    rc = dds_get_sample_rejected_status(entity_.handle(), &rejected);
    if (rc < 0) return dds_error("sample rejected status " + name_, rc);
    return static_cast<std::uint64_t>(lost.total_count) + rejected.total_count;
  }
  //! Number of matched writers now.
  Result<std::uint32_t> matched_writers() const {
    dds_subscription_matched_status_t status{};
    const dds_return_t rc = dds_get_subscription_matched_status(entity_.handle(), &status);
    if (rc < 0) return dds_error("subscription matched status " + name_, rc);
    return status.current_count;
  }
  //! Calls `callback(reader, arg)` on Cyclone's receive thread whenever samples arrive (no thread
  //! wake-up between the network and the callback); nullptr removes it, after waiting for a running
  //! callback to return. The callback may take and write; it must not delete entities.
  Status on_data_available(dds_on_data_available_fn callback, void* arg) const {
    dds_listener_t* listener = dds_create_listener(arg);
    if (callback != nullptr) dds_lset_data_available(listener, callback);
    const dds_return_t rc = dds_set_listener(entity_.handle(), callback != nullptr ? listener : nullptr);
    dds_delete_listener(listener);
    if (rc < 0) return dds_error("set listener " + name_, rc);
    return ok_status();
  }
  //! Enables the given communication statuses (DDS_*_STATUS) so a waitset can wake on them.
  Status enable_statuses(std::uint32_t mask) const {
    const dds_return_t rc = dds_set_status_mask(entity_.handle(), mask);
    if (rc < 0) return dds_error("status mask " + name_, rc);
    return ok_status();
  }
  dds_entity_t handle() const { return entity_.handle(); }
  const std::string& name() const { return name_; }

 private:
  Reader(Entity entity, std::string name) : entity_(std::move(entity)), name_(std::move(name)) {}
  Entity entity_;
  std::string name_;
};

//! A condition a waitset can wait on: a reader's "data available" read condition, or a guard.
class Condition {
 public:
  //! Triggers while the reader holds any sample.
  static Result<Condition> data_available(dds_entity_t reader);
  //! Set by hand (e.g. from a signal-handling thread) with trigger().
  static Result<Condition> guard(const Participant& participant);
  Status trigger() const;
  Status clear() const;
  dds_entity_t handle() const { return entity_.handle(); }

 private:
  explicit Condition(Entity entity) : entity_(std::move(entity)) {}
  Entity entity_;
};

//! A waitset: attach entities with a token, wait() returns the tokens of the triggered ones.
class WaitSet {
 public:
  static Result<WaitSet> create(const Participant& participant);
  //! Attaches a condition, or a reader/writer (triggers on its enabled statuses).
  Status attach(dds_entity_t entity, std::intptr_t token);
  //! Blocks up to `timeout` (negative: 0). `triggered` receives the tokens (empty on timeout).
  Status wait(std::chrono::nanoseconds timeout, std::vector<std::intptr_t>& triggered) const;

 private:
  explicit WaitSet(Entity entity) : entity_(std::move(entity)) {}
  Entity entity_;
  std::vector<dds_entity_t> attached_;
  mutable std::vector<dds_attach_t> results_;  //!< wait()'s scratch: no allocation per wake-up
};

//! Copies `text` into a bounded IDL string (char[N+1]); error if it does not fit.
template <std::size_t N>
Status copy_bounded(char (&dest)[N], const std::string& text, const char* field) {
  if (text.size() >= N) {
    return bad_input(std::string(field) + " '" + text + "' is longer than " + std::to_string(N - 1) +
                     " characters");
  }
  text.copy(dest, text.size());
  dest[text.size()] = '\0';
  return ok_status();
}

//! Moves a created entity into `slot`, or returns the error (for members created one by one).
template <class T>
Status assign(std::optional<T>& slot, Result<T> result) {
  if (!result) return result.error();
  slot.emplace(std::move(result).value());
  return ok_status();
}

}  // namespace tetra::dds
