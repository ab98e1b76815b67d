#include "tetra/dds/topics.hpp"

namespace tetra::dds {

Qos gyro_sample_qos(std::chrono::nanoseconds sample_period) {
  Qos qos;
  qos.reliable().volatile_durability().keep_last(kGyroSampleDepth).automatic_liveliness(kWriterLease);
  if (sample_period.count() > 0) qos.deadline(3 * sample_period);
  return qos;
}
Qos gyro_sample_reader_qos(std::chrono::nanoseconds sample_period) {
  // What the service needs and no more: the writers' automatic 1 s lease is not required of them
  // (a sensor driver that leaves liveliness at its default still matches); the deadline detects a
  // silent gyro.
  Qos qos;
  qos.reliable()
      .volatile_durability()
      .keep_last(kGyroSampleDepth)
      .automatic_liveliness(std::chrono::nanoseconds(DDS_INFINITY));
  if (sample_period.count() > 0) qos.deadline(3 * sample_period);
  return qos;
}
Qos reference_qos() {
  Qos qos;
  qos.reliable().volatile_durability().keep_last(kReferenceDepth);
  return qos;
}
Qos attitude_qos() {
  Qos qos;
  qos.reliable().volatile_durability().keep_last(1);
  return qos;
}
Qos attitude_writer_qos() {
  Qos qos;
  qos.reliable().volatile_durability().keep_last(kAttitudeWriterDepth);
  return qos;
}
Qos health_qos() {
  Qos qos;
  // Liveliness: a ground reader learns within a lease that the service is gone (kill -9 included).
  qos.reliable().transient_local(1).keep_last(1).automatic_liveliness(kWriterLease);
  return qos;
}
Qos event_qos() {
  Qos qos;
  qos.reliable().transient_local(kEventDepth).keep_last(kEventDepth);
  return qos;
}
Qos command_qos() {
  Qos qos;
  qos.reliable().volatile_durability().keep_last(kCommandDepth);
  return qos;
}

const char* qos_policy_name(std::uint32_t policy_id) {
  switch (policy_id) {
    case DDS_DURABILITY_QOS_POLICY_ID:
      return "durability";
    case DDS_PRESENTATION_QOS_POLICY_ID:
      return "presentation";
    case DDS_DEADLINE_QOS_POLICY_ID:
      return "deadline";
    case DDS_LATENCYBUDGET_QOS_POLICY_ID:
      return "latency budget";
    case DDS_OWNERSHIP_QOS_POLICY_ID:
      return "ownership";
    case DDS_LIVELINESS_QOS_POLICY_ID:
      return "liveliness";
    case DDS_RELIABILITY_QOS_POLICY_ID:
      return "reliability";
    case DDS_DESTINATIONORDER_QOS_POLICY_ID:
      return "destination order";
    case DDS_DATA_REPRESENTATION_QOS_POLICY_ID:
      return "data representation";
    default:
      return "unknown";
  }
}

Result<Topics> Topics::create(const Participant& participant) {
  auto gyro = Topic::create(participant, &tetra_GyroSample_desc, "GyroSample", gyro_sample_qos());
  if (!gyro) return gyro.error();
  auto reference =
      Topic::create(participant, &tetra_AttitudeReference_desc, "AttitudeReference", reference_qos());
  if (!reference) return reference.error();
  auto attitude = Topic::create(participant, &tetra_Attitude_desc, "Attitude", attitude_qos());
  if (!attitude) return attitude.error();
  auto health = Topic::create(participant, &tetra_Health_desc, "Health", health_qos());
  if (!health) return health.error();
  auto event = Topic::create(participant, &tetra_FdiEvent2_desc, "FdiEvent", event_qos());
  if (!event) return event.error();
  auto command = Topic::create(participant, &tetra_Command_desc, "Command", command_qos());
  if (!command) return command.error();
  return Topics{std::move(gyro).value(),   std::move(reference).value(), std::move(attitude).value(),
                std::move(health).value(), std::move(event).value(),     std::move(command).value()};
}

}  // namespace tetra::dds
