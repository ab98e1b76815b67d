#include "tetra/service/ros2_view_config.hpp"

#include <cctype>

namespace tetra::service {

namespace {

bool name_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}

}  // namespace

std::string ros2_name(const std::string& unit) {
  std::string out;
  for (const char c : unit) {
    const char mapped = name_char(c) ? c : '_';
    if (mapped == '_' && !out.empty() && out.back() == '_') continue;  // ROS forbids "__"
    out += mapped;
  }
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out.front())) != 0) out = "unit_" + out;
  while (out.size() > 1 && out.back() == '_') out.pop_back();
  return out;
}

bool is_ros2_name(const std::string& name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name.front())) != 0) return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (!name_char(name[i])) return false;
    if (i > 0 && name[i] == '_' && name[i - 1] == '_') return false;
  }
  return true;
}

Ros2ViewConfig Ros2ViewConfig::resolved(const std::string& unit) const {
  Ros2ViewConfig out = *this;
  if (out.name.empty()) out.name = ros2_name(unit);
  if (out.frame_id.empty()) out.frame_id = out.name + "_body";
  if (out.reference_frame_id.empty()) out.reference_frame_id = out.name + "_reference";
  return out;
}

std::string describe(const Ros2ViewConfig& config, const std::string& unit) {
  if (!config.enabled) return "ros2: off";
  const Ros2ViewConfig r = config.resolved(unit);
  return "ros2: rt/tetra/" + r.name + "/{attitude,imu}, rt/diagnostics (frames " + r.frame_id + ", " +
         r.reference_frame_id + ")";
}

Result<Ros2ViewConfig> ros2_view_config_from_yaml(const YAML::Node& node, const YamlReader& reader) {
  if (!node.IsMap()) return bad_input(reader.at(node) + "ros2 must be a map (enabled, name, frame_id, ...)");
  if (auto keys = reader.check_keys(node, {"enabled", "name", "frame_id", "reference_frame_id"}, "ros2");
      !keys)
    return keys.error();
  Ros2ViewConfig config;
  for (const auto& item : node) {
    const std::string& key = item.first.Scalar();
    const YAML::Node& value = item.second;
    const std::string text = value.IsScalar() ? value.Scalar() : std::string();
    if (key == "enabled") {
      if (text != "true" && text != "false")
        return bad_input(reader.at(value) + "ros2.enabled must be true or false");
      config.enabled = text == "true";
      continue;
    }
    if (!is_ros2_name(text)) {
      return bad_input(
          reader.at(value) + "ros2." + key + " '" + text +
          "' is not a ROS 2 name (letters, digits, single underscores; not starting with a digit)");
    }
    (key == "name" ? config.name : key == "frame_id" ? config.frame_id : config.reference_frame_id) = text;
  }
  return config;
}

}  // namespace tetra::service
