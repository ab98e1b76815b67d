#pragma once
// The six tetra topics and their QoS (docs/interfaces.md §4), created once per participant.

#include <chrono>
#include <cstdint>

#include "tetra.h"  // generated from idl/tetra.idl
#include "tetra/dds/entity.hpp"

namespace tetra::dds {

inline constexpr int kGyroSampleDepth = 64;
inline constexpr int kReferenceDepth = 8;
inline constexpr int kAttitudeWriterDepth = 128;
inline constexpr int kEventDepth = 256;  //!< events kept for late joiners, per unit
inline constexpr int kCommandDepth = 16;
inline constexpr int kMaxGyrosOnWire = tetra_MAX_GYROS;
//! GyroSample.flags bit: an AttitudeReference with this sample's stamp was written before it (by the same
//! publisher). A service holds the epoch until that reference is in (or its max_latency_s passes), so the
//! two topics need no common delivery order and the publisher no acknowledgement wait.
inline constexpr std::uint32_t kGyroFlagReferenceWritten = 0x8000'0000u;
inline bool reference_written(const tetra_GyroSample& sample) {
  return (sample.flags & kGyroFlagReferenceWritten) != 0;
}
//! GyroSample.flags bits 24-29: the number of gyro samples the publisher wrote for this stamp (0: not
//! said). `tetra play` in lockstep says it, and a service then fuses the epoch only with all of them (or
//! once a gyro missing from it has moved past it), however late they come: never one without a gyro
//! it was promised (docs/dds.md, "Playing a log").
inline constexpr unsigned kGyroFlagSamplesShift = 24;
inline constexpr std::uint32_t kGyroFlagSamplesMask = 0x3Fu << kGyroFlagSamplesShift;
inline int promised_samples(const tetra_GyroSample& sample) {
  return static_cast<int>((sample.flags & kGyroFlagSamplesMask) >> kGyroFlagSamplesShift);
}
inline constexpr std::chrono::milliseconds kWriterLease{1000};  //!< automatic liveliness of writers

//! reliable / volatile / keep-last 64; deadline = 3 × `sample_period` (none if zero).
Qos gyro_sample_qos(std::chrono::nanoseconds sample_period = std::chrono::nanoseconds{0});
//! What a GyroSample reader requests: gyro_sample_qos() without a liveliness requirement (automatic,
//! infinite lease), so a writer with the default liveliness and the table's other policies matches.
Qos gyro_sample_reader_qos(std::chrono::nanoseconds sample_period);
//! The name of a Cyclone QoS policy id (dds_qos_policy_id_t), e.g. "liveliness"; "unknown" otherwise.
const char* qos_policy_name(std::uint32_t policy_id);
Qos reference_qos();  //!< reliable / volatile / keep-last 8
Qos attitude_qos();   //!< reliable / volatile / keep-last 1
//! The service's Attitude writer: attitude_qos() keeping the last kAttitudeWriterDepth until acknowledged,
//! so a reader a moment behind (a recorder descheduled, a lockstep peer) loses none; small enough
//! (about 20 kB) never to hold the service's writes back.
Qos attitude_writer_qos();
Qos health_qos();   //!< reliable / transient-local / keep-last 1 / automatic liveliness, kWriterLease
Qos event_qos();    //!< reliable / transient-local / keep-last 256 (durability service 256)
Qos command_qos();  //!< reliable / volatile / keep-last 16

struct Topics {
  Topic gyro_sample;
  Topic reference;
  Topic attitude;
  Topic health;
  Topic event;
  Topic command;

  static Result<Topics> create(const Participant& participant);
};

}  // namespace tetra::dds
