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
//   * each sample's stamp is judged against the unit's clock first (the rule below); a stamp far
//     outside it is a time outlier (dropped, counted) and never moves the clock;
//   * per gyro, sequence numbers are compared with wrap-around (serial-number) arithmetic and must
//     increase: a repeat is a duplicate, a slightly smaller one is out of order (both dropped), a
//     jump counts the skipped numbers as a gap (the sample is kept) when the stamp moved far enough
//     for them (at most 2 per nominal period, + kSeqSlack); a larger jump either way is a sequence
//     discontinuity (dropped, counted): the gyro's numbering is re-anchored only when its next sample
//     continues from the new number. A stamp that does not increase is out of order (dropped); a
//     sample for an epoch already emitted is late (dropped); a gyro id outside 1..N is unknown
//     (dropped). All are counted;
//   * the clock: a stamp beyond ±kStampLimit_ns is always an outlier. Otherwise the unit's clock is
//     its newest accepted stamp carried forward by the receive clock (newest + speed · local time
//     since it arrived); a stamp is an outlier when it leads that clock by more than
//     `clock_window_ns`, lags the newest stamp by more than `clock_window_ns` + kMaxLagPeriods
//     periods, or lags the same gyro's last accepted stamp by more than `clock_window_ns`. Samples of
//     one writer are taken in order, so a delay never makes one lead by more than a period; a batch
//     taken at once lags by at most the reader's history (64 samples);
//   * a sensor clock that really jumped (forward or back) while samples flow: when every gyro not
//     absent has delivered kRestartSamples outliers that agree with each other by the same rule, and
//     no sample was accepted meanwhile, the assembler re-anchors on the new time base (as for a
//     restart: counted in sensor_restarts; the caller resets its pipeline); a lone outlier, or
//     outliers interleaved with good samples, never do;
//   * when every gyro is absent and any sample arrives, the unit resumes: all gyros are waited for
//     again (the caller re-arms their deadlines);
//   * when every gyro is absent and a sample comes back with a sequence number or stamp at or before
//     the last ones seen, the sensor restarted: the assembler forgets its time base (counted in
//     sensor_restarts; the caller resets its pipeline too) and starts again from that sample;
//   * attitude references are attached to the epoch whose stamp is within the tolerance of theirs. A
//     sample that says a reference for its stamp was written (`reference_written`) makes its epoch
//     wait for that reference too (within max_latency_ns like a sample), whatever order the two
//     streams arrive in. A reference for an epoch already emitted (a star tracker delivering late) goes
//     with the next epoch emitted, stamped with its own time (`fdi::Epoch::reference_stamp_ns`): the
//     pipeline fuses it at that time within its fusion horizon, or counts and reports it as too late.
//     Several waiting go one an epoch, oldest first, after an epoch's own reference (at most
//     kMaxLateReferences wait: the oldest beyond gives way, counted in references_crowded_out, and the
//     first of a run — until every waiting one has gone on — is said to the caller to report);
//   * a sample that says how many samples were written for its stamp (`promised`, lockstep play) makes
//     its epoch wait for all of them, however late, not max_latency_ns: it is emitted when they are in
//     or when a gyro missing from it has delivered a later stamp (its sample is lost). Such an epoch
//     waits as long for the reference its samples say was written (`reference_written`): until it is
//     in or some gyro has delivered a later stamp (the reference is lost, counted late if it comes).
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
  std::int64_t clock_window_ns =
      100'000'000;     //!< [ns] how far a stamp may lead the unit's clock; >= 2 periods
  double speed = 1.0;  //!< [-] sensor ns per local ns (a simulator X times real time: X); 0: the receive
                       //!< clock is not used (the unit's newest stamp is its clock)
};

constexpr std::int64_t kStampLimit_ns = std::int64_t{1} << 61;  //!< [ns] |stamp| beyond: outlier (73 years)
constexpr std::int64_t kMaxLagPeriods = 128;  //!< twice the gyro reader's history (64 samples)
constexpr int kRestartSamples = 3;            //!< agreeing outliers per gyro that re-anchor the clock
constexpr std::uint64_t kSeqSlack = 16;       //!< sequence numbers a gap may skip beyond 2 per period

//! Validates: N in 1..32, period > 0, 0 ≤ tolerance < period / 2, latency > 0, clock window ≥ 2 periods,
//! speed in [0, 1000]; errors name the field.
Status validate(const AssemblerConfig& config);

enum class Verdict : std::uint8_t {
  kAccepted,
  kDuplicate,
  kOutOfOrder,
  kLate,
  kUnknownGyro,
  kTimeOutlier,
  kSeqDiscontinuity
};
const char* to_string(Verdict verdict);

enum class AbsentReason : std::uint8_t { kDeadline, kLiveliness };

//! A late reference that gave way to newer ones (more than EpochAssembler::kMaxLateReferences waiting), when
//! it is the first of a run of them: for the caller to report (a `reference_late` event).
struct CrowdedOutReference {
  std::int64_t stamp_ns = 0;  //!< [ns] the reference's own stamp
  double late_s = 0.0;        //!< [s] the last emitted epoch's stamp minus it
};

class EpochAssembler {
 public:
  //! References for emitted epochs that may wait for an epoch to go with (the reference reader's history).
  static constexpr std::size_t kMaxLateReferences = 8;

  static Result<EpochAssembler> create(const AssemblerConfig& config);

  //! One gyro sample (raw may be NaN: that is for the pipeline to judge).
  //! `reference_written`: the sender wrote a reference for this stamp (the epoch waits for it).
  //! `promised`: the sender wrote this many samples for this stamp (0: not said); the epoch then waits
  //! for all of them, past max_latency_ns, until a gyro missing from it delivers a later stamp.
  Verdict add_sample(int gyro_id, std::uint64_t seq, std::int64_t stamp_ns, double raw, std::int64_t now_ns,
                     bool reference_written = false, int promised = 0);
  //! An attitude reference for the epoch at `stamp_ns` (one already emitted: with the next, at its stamp).
  //! Returns the reference crowded out by it when that starts a run of them (counted in either case).
  std::optional<CrowdedOutReference> add_reference(std::int64_t stamp_ns, const Quaternion& q_RB);
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
    bool awaits_reference = false;      //!< a sample said its reference was written
    int promised = 0;                   //!< samples the sender said it wrote for this stamp (0: not said)
  };
  struct GyroTrack {
    std::optional<std::uint64_t> last_seq;
    std::optional<std::uint64_t> jumped_seq;    //!< a discontinuous number, re-anchored if continued
    std::optional<std::int64_t> last_stamp_ns;  //!< [ns] latest accepted stamp
    bool absent = false;
  };
  //! A clock: the newest stamp seen on it and its local arrival time, and per gyro the newest stamp. The
  //! unit's clock, and the candidate clock a run of outliers builds.
  struct Clock {
    std::optional<std::int64_t> ref_stamp_ns;                //!< [ns] the newest stamp
    std::int64_t ref_local_ns = 0;                           //!< [ns] local time it arrived
    std::vector<std::optional<std::int64_t>> last_stamp_ns;  //!< [ns] per gyro (candidate only)
    std::vector<int> samples;                                //!< per gyro (candidate only)
  };

  explicit EpochAssembler(const AssemblerConfig& config);
  //! [ns] how far `stamp_ns` at local `now_ns` leads `clock` (negative: it lags).
  double lead_ns(const Clock& clock, std::int64_t stamp_ns, std::int64_t now_ns) const;
  //! Moves `clock`'s reference to this sample if it is the newest.
  void observe(Clock& clock, std::int64_t stamp_ns, std::int64_t now_ns) const;
  //! True when the stamp is within the window of `clock` and of `last_stamp_ns` (that gyro's newest).
  bool on_clock(const Clock& clock, std::optional<std::int64_t> last_stamp_ns, std::int64_t stamp_ns,
                std::int64_t now_ns) const;
  //! A time outlier: counted, and gathered into the candidate clock; re-anchors when it is confirmed.
  bool confirm_new_clock(std::size_t index, std::int64_t stamp_ns, std::int64_t now_ns);
  //! Forgets the time base (sequence numbers, stamps, open epochs, references); keeps absences.
  void forget_time_base();
  //! The sequence-number verdict (kAccepted: go on); counts gaps, duplicates, discontinuities.
  Verdict check_seq(GyroTrack& track, std::uint64_t seq, std::int64_t stamp_ns);
  bool ready(const Pending& epoch, std::int64_t now_ns) const;
  //! Every sample promised for the epoch is in, or a gyro missing from it moved past it (lost).
  bool promise_kept(const Pending& epoch) const;
  //! A reference within the tolerance of the epoch's stamp is in.
  bool reference_in(const Pending& epoch) const;
  //! Some gyro has delivered a stamp later than the epoch's.
  bool moved_past(const Pending& epoch) const;
  void emit(Pending& epoch, std::vector<fdi::Epoch>& out);

  AssemblerConfig config_;
  std::vector<GyroTrack> gyros_;
  std::deque<Pending> pending_;                                 //!< sorted by stamp
  std::deque<std::pair<std::int64_t, Quaternion>> references_;  //!< sorted by stamp
  //! references for epochs already emitted, sorted by stamp: each goes with one of the next epochs, at its
  //! own stamp (at most kMaxLateReferences wait; the oldest gives way)
  std::deque<std::pair<std::int64_t, Quaternion>> late_references_;
  bool crowding_ = false;  //!< a late reference was crowded out since late_references_ was last empty
  std::optional<std::int64_t> last_emitted_ns_;
  Clock clock_;                     //!< the unit's clock
  std::optional<Clock> candidate_;  //!< a new time base the outliers may be on
  AssemblerCounters counters_;
};

}  // namespace tetra::service
