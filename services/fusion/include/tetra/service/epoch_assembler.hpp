#pragma once
// Epoch assembler: turns N asynchronous gyro streams (one sample per gyro per sensor epoch, each
// with a per-gyro sequence number and a sensor stamp) into the pipeline's Epochs, in stamp order.
// Plain C++, no middleware: `tetra fusion` and `tetra record` feed it from DDS, tests feed it directly.
//
// Rules (docs/dds.md, "Epoch assembly"):
//   * samples whose stamps lie within `tolerance_ns` of an epoch's stamp belong to that epoch; the
//     epoch's stamp is the stamp of the sample that opened it;
//   * an epoch is emitted as soon as every gyro has delivered for it, has moved past it (delivered a
//     later stamp: its sample for this epoch is lost), or is marked absent (deadline missed,
//     liveliness lost); otherwise `max_latency_ns` of local time after it opened — a late or missing
//     sample never stalls the output. Gyros without a sample are `present = 0` in the epoch;
//   * per gyro, sequence numbers must increase by one: a repeat is a duplicate, a smaller one is out
//     of order (both dropped), a jump counts the skipped numbers as a gap (the sample is kept);
//     a stamp that does not increase is out of order (dropped); a sample for an epoch already
//     emitted is late (dropped); a gyro id outside 1..N is unknown (dropped). All are counted;
//   * when every gyro is absent and any sample arrives, the unit resumes: all gyros are waited for
//     again (the caller re-arms their deadlines);
//   * when every gyro is absent and a sample comes back with a sequence number or stamp at or before
//     the last ones seen, the sensor restarted: the assembler forgets its time base (counted in
//     sensor_restarts; the caller resets its pipeline too) and starts again from that sample;
//   * attitude references are attached to the epoch whose stamp is within the tolerance of theirs.
// Times: stamps are sensor time [ns]; `now_ns` is the caller's local monotonic clock [ns].

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/service_types/assembler_counters.hpp"

namespace tetra::service {

struct AssemblerConfig {
  int gyro_count = 4;                           //!< N, gyro ids 1..N
  std::int64_t nominal_period_ns = 10'000'000;  //!< [ns] expected sample period (100 Hz)
  std::int64_t tolerance_ns = 1'000'000;        //!< [ns] stamps this close belong to one epoch; < period / 2
  std::int64_t max_latency_ns = 20'000'000;     //!< [ns] longest local wait for an epoch's missing samples
};

//! Validates: N in 1..32, period > 0, 0 ≤ tolerance < period / 2, latency > 0; errors name the field.
Status validate(const AssemblerConfig& config);

enum class Verdict : std::uint8_t { kAccepted, kDuplicate, kOutOfOrder, kLate, kUnknownGyro };
const char* to_string(Verdict verdict);

enum class AbsentReason : std::uint8_t { kDeadline, kLiveliness };

class EpochAssembler {
 public:
  static Result<EpochAssembler> create(const AssemblerConfig& config);

  //! One gyro sample (raw may be NaN: that is for the pipeline to judge).
  Verdict add_sample(int gyro_id, std::uint64_t seq, std::int64_t stamp_ns, double raw, std::int64_t now_ns);
  //! An attitude reference for the epoch at `stamp_ns`.
  void add_reference(std::int64_t stamp_ns, const Quaternion& q_RB);
  //! The gyro's stream stopped (deadline missed or liveliness lost): epochs no longer wait for it.
  //! It is present again as soon as it delivers a sample.
  void mark_absent(int gyro_id, AbsentReason reason);
  bool absent(int gyro_id) const;
  //! True when every gyro is absent (the unit is silent).
  bool all_absent() const;

  //! Appends to `out` every epoch ready at local time `now_ns`, in increasing stamp order.
  void poll(std::int64_t now_ns, std::vector<fdi::Epoch>& out);
  //! Local time [ns] at which poll() must next be called (the oldest epoch's latency limit).
  std::optional<std::int64_t> next_due_ns() const;

  const AssemblerCounters& counters() const { return counters_; }
  AssemblerCounters& counters() { return counters_; }
  const AssemblerConfig& config() const { return config_; }

 private:
  struct Pending {
    std::int64_t stamp_ns = 0;          //!< [ns] sensor time of the sample that opened it
    std::int64_t opened_local_ns = 0;   //!< [ns] local time it was opened
    std::vector<double> raw;            //!< [V] per gyro
    std::vector<std::uint8_t> present;  //!< per gyro
  };
  struct GyroTrack {
    std::optional<std::uint64_t> last_seq;
    std::optional<std::int64_t> last_stamp_ns;  //!< [ns] latest accepted stamp
    bool absent = false;
  };

  explicit EpochAssembler(const AssemblerConfig& config);
  bool ready(const Pending& epoch, std::int64_t now_ns) const;
  void emit(Pending& epoch, std::vector<fdi::Epoch>& out);

  AssemblerConfig config_;
  std::vector<GyroTrack> gyros_;
  std::deque<Pending> pending_;                                 //!< sorted by stamp
  std::deque<std::pair<std::int64_t, Quaternion>> references_;  //!< sorted by stamp
  std::optional<std::int64_t> last_emitted_ns_;
  AssemblerCounters counters_;
};

}  // namespace tetra::service
