#include "tetra/ground/permissions.hpp"

#include <sstream>

#include "tetra/core/csv.hpp"

namespace tetra::ground {

Result<Permissions> Permissions::read(const std::string& path) {
  Permissions p;
  p.active_ = true;
  auto text = read_text_file(path);
  if (!text) return text.error();
  std::istringstream in(*text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    const std::string where = path + ":" + std::to_string(number);
    const auto first = line.find(':');
    const auto last = line.rfind(':');
    if (first == std::string::npos || last == first) return bad_input(where + ": expected WHO:UNIT:COMMANDS");
    Rule r;
    r.who = line.substr(0, first);
    r.unit = line.substr(first + 1, last - first - 1);
    if (r.who.empty() || r.unit.empty()) return bad_input(where + ": expected WHO:UNIT:COMMANDS");
    std::istringstream list(line.substr(last + 1));
    for (std::string c; std::getline(list, c, ',');) {
      if (c != "reset" && c != "exclude" && c != "reinstate" && c != "force" && c != "*")
        return bad_input(where + ": command '" + c + "': reset, exclude, reinstate, force or *");
      r.commands.insert(c);
    }
    if (r.commands.empty()) return bad_input(where + ": no command listed");
    p.rules_.push_back(std::move(r));
  }
  return p;
}

std::string Permissions::refusal(const std::string& user, const std::string& role,
                                 const CommandRequest& request) const {
  if (!active_) return "";
  const std::string action = request.kind == tetra_COMMAND_RESET     ? "reset"
                             : request.kind == tetra_COMMAND_EXCLUDE ? "exclude"
                                                                     : "reinstate";
  bool own = false;
  for (const auto& r : rules_) own = own || r.who == user;
  const std::string who = own ? user : "@" + role;
  for (const auto& r : rules_) {
    if (r.who != who || (r.unit != "*" && r.unit != request.unit)) continue;
    const bool any = r.commands.count("*") != 0;
    if ((any || r.commands.count(action) != 0) && (!request.force || any || r.commands.count("force") != 0))
      return "";
  }
  return "no permission for " + action + (request.force ? " with force" : "") + " on unit '" + request.unit +
         "' (" + (own ? "operator " + user : "role " + role) + ")";
}

}  // namespace tetra::ground
