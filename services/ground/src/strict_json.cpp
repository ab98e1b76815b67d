#include "tetra/ground/strict_json.hpp"

#include <set>
#include <vector>

namespace tetra::ground {

Result<nlohmann::json> parse_strict_json(const std::string& text) {
  using nlohmann::json;
  std::vector<std::set<std::string>> keys;  // one set per object being parsed
  std::string repeated;
  const json::parser_callback_t track = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (event == json::parse_event_t::object_end && !keys.empty()) {
      keys.pop_back();
    } else if (event == json::parse_event_t::key && !keys.empty() && parsed.is_string()) {
      if (!keys.back().insert(parsed.get<std::string>()).second && repeated.empty())
        repeated = parsed.get<std::string>();
    }
    return true;
  };
  json value = json::parse(text, track, false);
  if (value.is_discarded()) return bad_input("not JSON");
  if (!repeated.empty()) return bad_input("key '" + repeated + "' given twice");
  return value;
}

}  // namespace tetra::ground
