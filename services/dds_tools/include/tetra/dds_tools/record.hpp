#pragma once
// The gyro and reference streams of one unit on DDS, written as a replayable gyro log (docs/interfaces.md
// §2.2), as `tetra record` does. Epochs are assembled exactly as the fusion service does (same assembler,
// same settings when given the service's configuration), so a replay of the log sees the epochs the
// service saw. Optionally also the service's Attitude (docs/interfaces.md §2.4), FdiEvents (§2.5) and the
// operator commands it acknowledged.

#include <cstdint>
#include <ostream>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/report/argument_names.hpp"
#include "tetra/service/epoch_assembler.hpp"

namespace tetra::dds_tools {

struct RecordOptions {
  std::string unit;             //!< the unit to record; empty: the first one seen
  std::string out_path;         //!< gyro log to write (CSV, or HDF5 when named .h5)
  std::string config_path;      //!< fusion configuration: unit, gyro count, assembly settings; empty: none
  std::string attitude_path;    //!< the service's Attitude (CSV); empty: not recorded
  std::string events_path;      //!< the service's FdiEvents (JSON lines); empty: not recorded
  std::string commands_path;    //!< acknowledged operator commands (JSON lines); empty: not recorded
  int gyros = 4;                //!< number of gyros N (without config_path)
  double rate_hz = 100.0;       //!< [Hz] nominal sample rate (without config_path)
  double tolerance_s = -1.0;    //!< [s] stamps this close form one epoch; negative: a quarter period
  double max_latency_s = 0.02;  //!< [s] longest wait for an epoch's missing samples
  double duration_s = 0.0;      //!< [s] stop after this long; 0: no limit
  bool until_idle = false;      //!< stop when the gyro writers have come and gone
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  //! How messages name the arguments (out_path, config_path, ...) and the command ("command").
  report::ArgumentNames names;
};

struct Recorded {
  std::string unit;                     //!< the unit recorded; empty: none seen
  std::uint64_t epochs = 0;             //!< epochs written
  service::AssemblerCounters counters;  //!< the assembler's counters
  std::uint64_t gyro_samples_lost = 0;  //!< GyroSample lost on the wire (writers' history overflowed)
  std::uint64_t attitudes_lost = 0;     //!< Attitude lost on the wire (with --attitude)
};

//! Records until `shutdown`, the duration, or (until_idle) the gyro writers gone and the service's last
//! outputs in; the files are written all or none (through the output layer). Notes go to `err`.
//! Samples lost on the wire (a writer's history dropped them before this recorder had them) are counted
//! in the result: the command then fails, saying how many, and the log lacks those samples.
//! `shutdown` (SIGINT/SIGTERM) wakes the wait.
Result<Recorded> record_unit(const RecordOptions& options, dds::ShutdownSignal& shutdown, std::ostream& err);

}  // namespace tetra::dds_tools
