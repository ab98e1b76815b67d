#include "tetra/ground/command_request.hpp"

#include <nlohmann/json.hpp>

#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/ground/strict_json.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {

using nlohmann::json;

namespace {

//! The text of `key` when `j` has it as a string; nullopt when absent; an error when it is not a string.
Result<std::optional<std::string>> optional_text(const json& j, const char* key) {
  if (!j.contains(key)) return std::optional<std::string>();
  if (!j[key].is_string()) return bad_input(std::string("command: field '") + key + "' must be a string");
  return std::optional<std::string>(j[key].get<std::string>());
}

//! The unit a command names by its field `unit` or `unit_id`.
Result<std::string> command_unit(const json& j) {
  auto name = optional_text(j, "unit");
  if (!name) return name.error();
  auto id = optional_text(j, "unit_id");
  if (!id) return id.error();
  return requested_unit(*name, *id, "command: field");
}

}  // namespace

Result<CommandRequest> parse_command_request(const std::string& body, const std::string& operator_id,
                                             const std::string& origin) {
  auto parsed = parse_strict_json(body);
  if (!parsed) return bad_input("command: " + parsed.error().message);
  const json& j = *parsed;
  if (!j.is_object()) return bad_input("command: the body is not a JSON object");
  for (const auto& item : j.items()) {
    if (item.key() == "operator")
      return bad_input("command: field 'operator' is not accepted: the operator is the signed-in user");
    if (item.key() != "unit" && item.key() != "unit_id" && item.key() != "action" && item.key() != "gyro" &&
        item.key() != "force")
      return bad_input("command: field '" + item.key() + "' unknown (unit or unit_id, action, gyro, force)");
  }
  CommandRequest c;
  c.origin = origin;
  c.operator_id = operator_id;
  auto unit = command_unit(j);
  if (!unit) return unit.error();
  c.unit = std::move(unit).value();
  const std::string action =
      j.contains("action") && j["action"].is_string() ? j["action"].get<std::string>() : "";
  if (action == "reset") {
    c.kind = tetra_COMMAND_RESET;
  } else if (action == "exclude") {
    c.kind = tetra_COMMAND_EXCLUDE;
  } else if (action == "reinstate") {
    c.kind = tetra_COMMAND_REINSTATE;
  } else {
    return bad_input("command: field 'action' must be reset, exclude or reinstate");
  }
  if (j.contains("gyro") && !j["gyro"].is_number_integer())
    return bad_input("command: field 'gyro' must be an integer");
  c.gyro = j.contains("gyro") && j["gyro"].is_number_integer() && j["gyro"].get<std::int64_t>() <= 1000
               ? static_cast<int>(j["gyro"].get<std::int64_t>())
               : (j.contains("gyro") ? -1 : 0);
  if (c.kind != tetra_COMMAND_RESET && (c.gyro < 1 || c.gyro > dds::kMaxGyrosOnWire))
    return bad_input("command: field 'gyro' must be 1.." + std::to_string(dds::kMaxGyrosOnWire));
  if (c.kind == tetra_COMMAND_RESET && c.gyro != 0) return bad_input("command: reset takes no 'gyro'");
  if (j.contains("force") && !j["force"].is_boolean())
    return bad_input("command: field 'force' must be true or false");
  c.force = j.contains("force") && j["force"].get<bool>();
  return c;
}

Status to_wire(const CommandRequest& request, std::uint64_t command_id, tetra_Command& out) {
  out = tetra_Command{};
  if (auto s = dds::copy_bounded(out.unit, request.unit, "unit"); !s) return s;
  if (auto s = dds::copy_bounded(out.operator_id, request.operator_id, "operator"); !s) return s;
  if (auto s = dds::copy_bounded(out.origin, request.origin, "origin"); !s) return s;
  out.command_id = command_id;
  out.kind = request.kind;
  out.gyro = static_cast<std::int16_t>(request.gyro);
  out.force = request.force;
  return ok_status();
}

}  // namespace tetra::ground
