#pragma once
// The epoch assembler's counters (services/fusion): plain data, below both the service and the DDS
// layer, which puts them on the wire in Health (docs/dds.md, "Epoch assembly").

#include <cstdint>

namespace tetra::service {

struct AssemblerCounters {
  std::uint64_t epochs_emitted = 0;
  std::uint64_t samples_late = 0;           //!< arrived after their epoch was emitted
  std::uint64_t samples_duplicate = 0;      //!< sequence number repeated
  std::uint64_t samples_out_of_order = 0;   //!< sequence number or stamp going backwards
  std::uint64_t samples_gap = 0;            //!< sequence numbers skipped
  std::uint64_t samples_unknown_gyro = 0;   //!< gyro id outside 1..N
  std::uint64_t samples_other_unit = 0;     //!< other units' samples (counted by the caller)
  std::uint64_t sensor_restarts = 0;        //!< time base restarted (after silence, or re-anchored)
  std::uint64_t references_late = 0;        //!< references for epochs already emitted, and announced ones
                                            //!< (reference_written) their epoch went without
  std::uint64_t deadlines_missed = 0;       //!< counted by the caller through mark_absent()
  std::uint64_t liveliness_lost = 0;        //!< counted by the caller through mark_absent()
  std::uint64_t time_outlier = 0;           //!< stamps far outside the unit's clock (dropped)
  std::uint64_t seq_discontinuity = 0;      //!< sequence numbers jumping further than time explains
  std::uint64_t unit_silences = 0;          //!< counted by the caller: every gyro silent at once
  std::uint64_t samples_promised_lost = 0;  //!< said written for an epoch (promised) that went without them
  //! references for emitted epochs crowded out: the oldest of more than EpochAssembler::kMaxLateReferences
  //! waiting gives way (on the wire within Health.references_too_late: left out like one beyond the horizon)
  std::uint64_t references_crowded_out = 0;
};

}  // namespace tetra::service
