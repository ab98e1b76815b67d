#pragma once
// Conversions between the generated IDL types and the libraries' types — and nothing else.
// Wire units are SI, like the libraries'; only the names change.

#include <array>
#include <cstdint>
#include <string>

#include "tetra.h"  // generated from idl/tetra.idl
#include "tetra/core/result.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/service_types/assembler_counters.hpp"

namespace tetra::dds {

tetra_Mode to_wire(fdi::Mode mode);
fdi::Mode from_wire(tetra_Mode mode);
tetra_FaultKind to_wire(fdi::FaultKind kind);
fdi::FaultKind from_wire(tetra_FaultKind kind);
tetra_GyroState to_wire(fdi::GyroState state);
fdi::GyroState from_wire(tetra_GyroState state);
tetra_EventType to_wire(fdi::EventType type);
fdi::EventType from_wire(tetra_EventType type);

//! Text of a bounded IDL string (stops at the terminator or the array's end).
template <std::size_t N>
std::string from_wire(const char (&text)[N]) {
  std::size_t n = 0;
  while (n < N && text[n] != '\0') ++n;
  return std::string(text, n);
}

Status to_wire(const std::string& unit, const fdi::AttitudeEstimate& attitude, tetra_Attitude& out);
fdi::AttitudeEstimate from_wire(const tetra_Attitude& in);

//! Health as it goes on the wire: the pipeline's health plus the assembler's counters.
//! Owns the buffer of the bounded per-gyro sequence.
struct WireHealth {
  tetra_Health msg{};
  std::array<tetra_GyroStatus, tetra_MAX_GYROS> gyros{};
};
Status to_wire(const std::string& unit, const fdi::Health& health, const service::AssemblerCounters& counters,
               WireHealth& out);

//! Health read back from the wire.
struct HealthView {
  std::string unit;
  fdi::Health health;
  service::AssemblerCounters counters;
  std::uint64_t events_published = 0;  //!< event_seq of the service's last event
  std::uint32_t gyro_writers = 0;      //!< GyroSample writers the service has matched
  double health_period_s = 0.0;        //!< [s] the service writes Health at least this often
  double reference_horizon_s = 0.0;    //!< [s] the service's fusion horizon for late references
};
HealthView from_wire(const tetra_Health& in);

//! What an acknowledgement says of the command it answers (audit trail).
struct CommandAudit {
  tetra_CommandKind kind = tetra_COMMAND_RESET;
  bool force = false;
  std::string operator_id;
  std::string origin;
};
//! "reset", "exclude", "reinstate".
const char* to_string(tetra_CommandKind kind);

//! An event with its per-run sequence number and, for acknowledgements, the command's id and audit.
struct EventView {
  std::string unit;
  std::uint64_t event_seq = 0;
  std::uint64_t command_id = 0;
  fdi::FdiEvent event;
  CommandAudit command;  //!< acknowledgements (command_id != 0) only
};
//! An event on the wire, with the storage its ledger rows point into.
struct WireEvent {
  tetra_FdiEvent2 msg{};
  std::array<tetra_LedgerRow, tetra_LEDGER_ROWS_MAX> rows{};
};
//! The whole event: its detail (up to 1023 bytes: every text of the pipeline; a longer one ends with
//! "[cut: N bytes not sent]") and its ledger rows (beyond 40, `ledger_dropped` counts them).
Status to_wire(const EventView& view, WireEvent& out);
EventView from_wire(const tetra_FdiEvent2& in);

}  // namespace tetra::dds
