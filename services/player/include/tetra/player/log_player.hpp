#pragma once
// `tetra play`: a recorded gyro log (CSV, HDF5 or TDMS) back on the wire, as the unit would publish it
// (docs/dds.md, "Playing a log"). Each epoch's delivered gyro samples go out as GyroSample (stamp_ns = the
// log's time, seq = the epoch's count, raw = the logged value) after its AttitudeReference when the log
// has one; the DDS source timestamp is the wall clock of the write, as for `tetra sim --dds`. Paced by the
// log's own times at `speed`, or in lockstep (speed 0: each epoch waits for the service's Attitude of it,
// so the service sees exactly what `tetra replay` sees).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"

namespace tetra::dds {
class ShutdownSignal;
}

namespace tetra::player {

struct PlayOptions {
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  std::string unit;                 //!< DDS key; empty: the log's "# unit=" comment, else "tetra-1"
  double speed = 1.0;               //!< 1 = the log's pace, X = X times faster, 0 = lockstep
  bool loop = false;                //!< start again at the end (times keep increasing, see log_player.cpp)
  std::optional<double> start_s;    //!< [s] first log time played (inclusive)
  std::optional<double> end_s;      //!< [s] last log time played (inclusive)
  int wait_readers = 1;             //!< GyroSample readers to wait for before the first sample
  double wait_timeout_s = 10.0;     //!< [s] give up waiting for them
  double lockstep_timeout_s = 2.0;  //!< [s] lockstep: longest wait for an epoch's Attitude
};

struct PlayReport {
  std::string unit;                    //!< the key the samples went out with
  std::uint64_t epochs = 0;            //!< epochs published
  std::uint64_t samples = 0;           //!< GyroSample written
  std::uint64_t references = 0;        //!< AttitudeReference written
  std::uint64_t passes = 0;            //!< passes over the log (1 without --loop)
  std::uint64_t attitudes = 0;         //!< Attitude of this unit received
  std::uint64_t lockstep_missing = 0;  //!< lockstep: epochs whose Attitude did not come in time
  double first_time_s = 0.0;           //!< [s] log time of the first epoch published
  double last_time_s = 0.0;            //!< [s] log time of the last epoch published
  double wall_s = 0.0;                 //!< [s] publishing time
  double worst_lag_ms = 0.0;           //!< [ms] paced: worst lateness of a write behind its due time
};

//! Plays the log until its end (every pass with `loop`: until a shutdown signal). `on_progress` is
//! called about once per wall-clock second. Errors: the log's (file, line), a dps log (the wire carries
//! volts), no epoch in [start, end], DDS failures, no reader within the timeout.
Result<PlayReport> play_log(const std::string& path, const PlayOptions& options,
                            dds::ShutdownSignal* shutdown,
                            const std::function<void(const PlayReport&)>& on_progress = {});

}  // namespace tetra::player
