#pragma once
// Per-unit and per-command permissions of commanders (docs/ground.md, "Permissions"): a file of
// `WHO:UNIT:COMMANDS` lines, WHO a user name or `@commander` (the role), UNIT a unit's name (any
// characters, colons too) or `*`, COMMANDS a comma list of reset, exclude, reinstate, force, or `*`.
// Without the file a commander may send every command to every unit; with it, only what a line of the
// operator's own (or, when the operator has none, of the role) grants.

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/ground/command_request.hpp"

namespace tetra::ground {

class Permissions {
 public:
  //! Everything allowed.
  Permissions() = default;
  //! The rules of a file; errors name the file and line.
  static Result<Permissions> read(const std::string& path);
  //! Why `user` of `role` may not send `request` ("" when allowed).
  std::string refusal(const std::string& user, const std::string& role, const CommandRequest& request) const;

 private:
  struct Rule {
    std::string who;
    std::string unit;
    std::set<std::string> commands;
  };
  bool active_ = false;
  std::vector<Rule> rules_;
};

}  // namespace tetra::ground
