#pragma once
// An operator command as clients give it (the browser's JSON POST, `tetra command`'s options), its
// validation, and its wire form. Every command names its operator and origin (audit trail).

#include <cstdint>
#include <string>

#include "tetra.h"  // generated from idl/tetra.idl
#include "tetra/core/result.hpp"

namespace tetra::ground {

//! An operator command as the browser posts it: {"unit", "action", "gyro", "force"}; the operator is
//! the signed-in user, never a field of the request.
struct CommandRequest {
  std::string unit;
  tetra_CommandKind kind = tetra_COMMAND_RESET;
  int gyro = 0;
  bool force = false;
  std::string operator_id;
  std::string origin;  //!< set by the server: "ground@<client address>"
};
//! Validates a POST body (no other keys, none twice); errors name the field.
Result<CommandRequest> parse_command_request(const std::string& body, const std::string& operator_id,
                                             const std::string& origin);

//! The wire form; errors when a text is longer than the wire's bound.
Status to_wire(const CommandRequest& request, std::uint64_t command_id, tetra_Command& out);

}  // namespace tetra::ground
