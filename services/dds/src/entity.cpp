#include "tetra/dds/entity.hpp"

#include <algorithm>

namespace tetra::dds {

Error dds_error(const std::string& what, dds_return_t rc) {
  return failure("DDS " + what + ": " + dds_strretcode(rc));
}

namespace {

DataRepresentation& process_data_representation() {
  static DataRepresentation representation = DataRepresentation::kXcdr1;
  return representation;
}

dds_data_representation_id_t wire_id(DataRepresentation representation) {
  return representation == DataRepresentation::kXcdr1 ? DDS_DATA_REPRESENTATION_XCDR1
                                                      : DDS_DATA_REPRESENTATION_XCDR2;
}

std::optional<service::SecurityProfile>& process_security_profile() {
  static std::optional<service::SecurityProfile> profile;
  return profile;
}

//! Cyclone's built-in plugins (libdds_security_{auth,ac,crypto}) and the profile's documents.
void set_security_properties(dds_qos_t* qos, const service::SecurityProfile& p) {
  const auto file = [](const std::string& path) { return "file:" + path; };
  dds_qset_prop(qos, "dds.sec.auth.library.path", "dds_security_auth");
  dds_qset_prop(qos, "dds.sec.auth.library.init", "init_authentication");
  dds_qset_prop(qos, "dds.sec.auth.library.finalize", "finalize_authentication");
  dds_qset_prop(qos, "dds.sec.auth.identity_ca", file(p.identity_ca).c_str());
  dds_qset_prop(qos, "dds.sec.auth.identity_certificate", file(p.identity_certificate).c_str());
  dds_qset_prop(qos, "dds.sec.auth.private_key", file(p.private_key).c_str());
  dds_qset_prop(qos, "dds.sec.access.library.path", "dds_security_ac");
  dds_qset_prop(qos, "dds.sec.access.library.init", "init_access_control");
  dds_qset_prop(qos, "dds.sec.access.library.finalize", "finalize_access_control");
  dds_qset_prop(qos, "dds.sec.access.permissions_ca", file(p.permissions_ca).c_str());
  dds_qset_prop(qos, "dds.sec.access.governance", file(p.governance).c_str());
  dds_qset_prop(qos, "dds.sec.access.permissions", file(p.permissions).c_str());
  dds_qset_prop(qos, "dds.sec.crypto.library.path", "dds_security_crypto");
  dds_qset_prop(qos, "dds.sec.crypto.library.init", "init_crypto");
  dds_qset_prop(qos, "dds.sec.crypto.library.finalize", "finalize_crypto");
}

}  // namespace

void set_data_representation(DataRepresentation representation) {
  process_data_representation() = representation;
}
DataRepresentation data_representation() {
  return process_data_representation();
}

void set_security_profile(std::optional<service::SecurityProfile> profile) {
  process_security_profile() = std::move(profile);
}

void Entity::reset() {
  if (handle_ > 0) (void)dds_delete(handle_);
  handle_ = 0;
}

Qos::Qos() : qos_(dds_create_qos()) {}
Qos::~Qos() {
  if (qos_ != nullptr) dds_delete_qos(qos_);
}

Qos& Qos::reliable(std::chrono::nanoseconds max_blocking) {
  dds_qset_reliability(qos_, DDS_RELIABILITY_RELIABLE, max_blocking.count());
  return *this;
}
Qos& Qos::best_effort() {
  dds_qset_reliability(qos_, DDS_RELIABILITY_BEST_EFFORT, 0);
  return *this;
}
Qos& Qos::keep_last(int depth) {
  dds_qset_history(qos_, DDS_HISTORY_KEEP_LAST, depth);
  return *this;
}
Qos& Qos::keep_all() {
  dds_qset_history(qos_, DDS_HISTORY_KEEP_ALL, DDS_LENGTH_UNLIMITED);
  return *this;
}
Qos& Qos::volatile_durability() {
  dds_qset_durability(qos_, DDS_DURABILITY_VOLATILE);
  return *this;
}
Qos& Qos::transient_local(int depth) {
  dds_qset_durability(qos_, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_durability_service(qos_, 0, DDS_HISTORY_KEEP_LAST, depth, DDS_LENGTH_UNLIMITED,
                              DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  return *this;
}
Qos& Qos::deadline(std::chrono::nanoseconds period) {
  dds_qset_deadline(qos_, period.count());
  return *this;
}
Qos& Qos::automatic_liveliness(std::chrono::nanoseconds lease) {
  dds_qset_liveliness(qos_, DDS_LIVELINESS_AUTOMATIC, lease.count());
  return *this;
}
Qos& Qos::no_autodispose() {
  dds_qset_writer_data_lifecycle(qos_, false);
  return *this;
}
Qos& Qos::partition(const std::string& name) {
  dds_qset_partition1(qos_, name.c_str());
  return *this;
}
Qos& Qos::data_representation(DataRepresentation representation) {
  const dds_data_representation_id_t id = wire_id(representation);
  dds_qset_data_representation(qos_, 1, &id);
  return *this;
}
Qos& Qos::accept_xcdr1_and_xcdr2() {
  const dds_data_representation_id_t ids[] = {DDS_DATA_REPRESENTATION_XCDR1, DDS_DATA_REPRESENTATION_XCDR2};
  dds_qset_data_representation(qos_, 2, ids);
  return *this;
}
bool Qos::has_data_representation() const {
  uint32_t n = 0;
  dds_data_representation_id_t* ids = nullptr;
  const bool present = dds_qget_data_representation(qos_, &n, &ids);
  dds_free(ids);
  return present;
}
Qos Qos::copy() const {
  Qos out;
  (void)dds_copy_qos(out.qos_, qos_);
  return out;
}

std::string unit_partition(const std::string& unit) {
  return "tetra." + (unit.empty() ? std::string("*") : unit);
}

Qos Participant::endpoint_qos(const Qos& qos) const {
  Qos out = qos.copy();
  if (!partition_.empty()) out.partition(partition_);
  return out;
}

Qos Participant::writer_qos(const Qos& qos) const {
  Qos out = endpoint_qos(qos);
  if (!out.has_data_representation()) out.data_representation(process_data_representation());
  return out;
}
Qos Participant::reader_qos(const Qos& qos) const {
  Qos out = endpoint_qos(qos);
  if (!out.has_data_representation()) out.accept_xcdr1_and_xcdr2();
  return out;
}

Result<Participant> Participant::create(dds_domainid_t domain, const std::string& unit) {
  const auto& security = process_security_profile();
  // A unit name is a partition name here: pattern characters would widen the grant's reach.
  if (security && unit.find_first_of("*?[]\\") != std::string::npos) {
    return bad_input("unit '" + unit + "': with DDS Security a unit name cannot contain * ? [ ] or \\");
  }
  Qos qos;
  if (security) set_security_properties(qos.mutable_qos(), *security);
  const dds_entity_t handle = dds_create_participant(domain, security ? qos.get() : nullptr, nullptr);
  if (handle < 0) {
    return dds_error("create participant on domain " + std::to_string(domain) +
                         (security ? " with DDS Security profile " + security->source : std::string()),
                     handle);
  }
  return Participant(Entity(handle), security ? unit_partition(unit) : std::string());
}

Result<Topic> Topic::create(const Participant& participant, const dds_topic_descriptor_t* descriptor,
                            const std::string& name, const Qos& qos) {
  const dds_entity_t handle =
      dds_create_topic(participant.handle(), descriptor, name.c_str(), qos.get(), nullptr);
  if (handle < 0) return dds_error("create topic " + name, handle);
  return Topic(Entity(handle), name);
}

Result<Condition> Condition::data_available(dds_entity_t reader) {
  const dds_entity_t handle = dds_create_readcondition(reader, DDS_ANY_STATE);
  if (handle < 0) return dds_error("create read condition", handle);
  return Condition(Entity(handle));
}

Result<Condition> Condition::guard(const Participant& participant) {
  const dds_entity_t handle = dds_create_guardcondition(participant.handle());
  if (handle < 0) return dds_error("create guard condition", handle);
  return Condition(Entity(handle));
}

Status Condition::trigger() const {
  const dds_return_t rc = dds_set_guardcondition(entity_.handle(), true);
  if (rc < 0) return dds_error("set guard condition", rc);
  return ok_status();
}

Status Condition::clear() const {
  const dds_return_t rc = dds_set_guardcondition(entity_.handle(), false);
  if (rc < 0) return dds_error("clear guard condition", rc);
  return ok_status();
}

Result<WaitSet> WaitSet::create(const Participant& participant) {
  const dds_entity_t handle = dds_create_waitset(participant.handle());
  if (handle < 0) return dds_error("create waitset", handle);
  return WaitSet(Entity(handle));
}

Status WaitSet::attach(dds_entity_t entity, std::intptr_t token) {
  const dds_return_t rc = dds_waitset_attach(entity_.handle(), entity, static_cast<dds_attach_t>(token));
  if (rc < 0) return dds_error("attach to waitset", rc);
  attached_.push_back(entity);
  return ok_status();
}

Status WaitSet::wait(std::chrono::nanoseconds timeout, std::vector<std::intptr_t>& triggered) const {
  results_.resize(std::max<std::size_t>(attached_.size(), 1));
  const dds_return_t n = dds_waitset_wait(entity_.handle(), results_.data(), results_.size(),
                                          std::max<std::int64_t>(timeout.count(), 0));
  if (n < 0) return dds_error("wait", n);
  triggered.clear();
  for (dds_return_t i = 0; i < std::min<dds_return_t>(n, static_cast<dds_return_t>(results_.size())); ++i)
    triggered.push_back(static_cast<std::intptr_t>(results_[static_cast<std::size_t>(i)]));
  return ok_status();
}

}  // namespace tetra::dds
