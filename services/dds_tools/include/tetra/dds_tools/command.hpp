#pragma once
// An operator command to a unit's fusion service over DDS, as `tetra command` sends it: waits for a
// service to match, sends the Command (with the operator's id and the origin) and waits for its
// acknowledgement (an FdiEvent carrying the command's id).

#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/ground/command_request.hpp"

namespace tetra::dds_tools {

struct CommandOptions {
  ground::CommandRequest request;  //!< unit, gyro, force, operator and origin (its kind is set from `action`)
  std::string action;              //!< reset, exclude or reinstate
  double timeout_s = 5.0;          //!< [s] wait this long for a service and its acknowledgement
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
};

//! Error::subject of force given with another action than exclude.
inline constexpr const char* kSubjectForce = "force";

//! Sends the command; the acknowledgement (accepted or refused: ack.event.refused()). A failure when no
//! service answers within the timeout.
Result<dds::EventView> send_command(const CommandOptions& options);

//! The acknowledgement as one JSON line (no newline): the event (docs/interfaces.md §2.5 form, with
//! "accepted") after the command's id and audit fields.
std::string command_ack_line(const dds::EventView& ack);

}  // namespace tetra::dds_tools
