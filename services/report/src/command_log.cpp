#include "tetra/report/command_log.hpp"

#include <nlohmann/json.hpp>

#include <set>
#include <sstream>

#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/units.hpp"

namespace tetra::report {

namespace {

using Json = nlohmann::json;

Result<RecordedCommand> parse_line(const std::string& line, const std::string& where) {
  // A key given twice is refused (JSON leaves its meaning open; the parser would keep the last).
  std::set<std::string> keys;
  std::string repeated;
  const Json::parser_callback_t note_keys = [&](int depth, Json::parse_event_t event, Json& parsed) {
    if (event == Json::parse_event_t::key && depth == 1 && parsed.is_string() &&
        !keys.insert(parsed.get<std::string>()).second && repeated.empty()) {
      repeated = parsed.get<std::string>();
    }
    return true;
  };
  const Json j = Json::parse(line, note_keys, false);
  if (j.is_discarded() || !j.is_object()) return bad_input(where + ": not a JSON object");
  if (!repeated.empty()) return bad_input(where + ": field '" + repeated + "' appears twice");
  RecordedCommand c;
  if (!j.contains("time_s") || !j["time_s"].is_number())
    return bad_input(where + ": field 'time_s' (number) missing");
  if (auto why = log_time_problem(j["time_s"].get<double>()))
    return bad_input(where + ": field 'time_s': " + *why);
  c.stamp_ns = seconds_to_ns(j["time_s"].get<double>());
  if (!j.contains("command") || !j["command"].is_string())
    return bad_input(where + ": field 'command' missing");
  c.action = j["command"].get<std::string>();
  if (c.action != "reset" && c.action != "exclude" && c.action != "reinstate")
    return bad_input(where + ": field 'command' must be reset, exclude or reinstate");
  if (c.action != "reset") {
    if (!j.contains("gyro")) return bad_input(where + ": field 'gyro' missing");
    const Json& gyro = j["gyro"];
    if (!gyro.is_number_integer()) {
      return bad_input(where + ": field 'gyro' must be a whole number (a gyro id 1..64), not " + gyro.dump());
    }
    if (gyro.get<double>() < 1 || gyro.get<double>() > 64) {
      return bad_input(where + ": field 'gyro' " + gyro.dump() + " is outside 1..64");
    }
    c.gyro = static_cast<int>(gyro.get<std::int64_t>());
  }
  if (j.contains("force")) {
    if (!j["force"].is_boolean()) return bad_input(where + ": field 'force' must be true or false");
    c.force = j["force"].get<bool>();
  }
  return c;
}

}  // namespace

Result<std::vector<RecordedCommand>> read_command_log(const std::string& path) {
  auto text = read_text_file(path);
  if (!text) return text.error();
  std::vector<RecordedCommand> commands;
  std::istringstream in(*text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    auto c = parse_line(line, path + ":" + std::to_string(number));
    if (!c) return c.error();
    if (!commands.empty() && c->stamp_ns < commands.back().stamp_ns)
      return bad_input(path + ":" + std::to_string(number) + ": field 'time_s' goes backwards");
    commands.push_back(std::move(c).value());
  }
  return commands;
}

fdi::FdiEvent apply(fdi::Pipeline& pipeline, const RecordedCommand& command) {
  if (command.action == "exclude") return pipeline.exclude(command.gyro, command.stamp_ns, command.force);
  if (command.action == "reinstate") return pipeline.reinstate(command.gyro, command.stamp_ns);
  return pipeline.reset_command(command.stamp_ns);
}

}  // namespace tetra::report
