#pragma once
// Reading optional scenario fields (private to tetra::sim): shared by the scenario and the
// closed-loop sections.

#include <algorithm>
#include <cstdlib>
#include <initializer_list>
#include <string>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "tetra/core/result.hpp"
#include "tetra/core/yaml_reader.hpp"

namespace tetra::sim {

// Sets `out` from parent[key] when the key is present; leaves the default otherwise.
inline Status maybe_number(const YamlReader& yaml, const YAML::Node& parent, const std::string& key,
                           const std::string& what, double& out) {
  const YAML::Node node = parent[key];
  if (!node) return ok_status();
  auto v = yaml.number(node, YamlReader::child(what, key));
  if (!v) return v.error();
  out = *v;
  return ok_status();
}

inline Status maybe_numbers(const YamlReader& yaml, const YAML::Node& parent, const std::string& what,
                            std::initializer_list<std::pair<const char*, double*>> fields) {
  for (const auto& [key, out] : fields) {
    if (Status st = maybe_number(yaml, parent, key, what, *out); !st) return st;
  }
  return ok_status();
}

// The node a range error names by its first word ("acs.amplitude_deg must ...", "slews[1].angle_deg ...",
// "closed_loop: ..."): the deepest key of that path present in the file, else the root.
inline YAML::Node node_named(const YAML::Node& root, const std::string& message) {
  const std::string path = message.substr(0, message.find_first_of(" :"));
  YAML::Node node(root);  // rebound with reset(): yaml-cpp's assignment would write into the tree
  std::size_t begin = 0;
  while (begin < path.size()) {
    const std::size_t end = std::min(path.find_first_of(".[", begin), path.size());
    const YAML::Node& here = node;
    const YAML::Node next = here.IsMap() ? here[path.substr(begin, end - begin)] : YAML::Node();
    if (!next) break;
    node.reset(next);
    begin = end + 1;
    if (end < path.size() && path[end] == '[') {  // "slews[1]"
      const std::size_t i = std::strtoul(path.c_str() + begin, nullptr, 10);
      const YAML::Node& list = node;
      if (!list.IsSequence() || i >= list.size()) break;
      node.reset(list[i]);
      begin = path.find(']', begin);
      if (begin == std::string::npos) break;
      begin += 2;
    }
  }
  return node;
}

inline Result<Eigen::Vector3d> axis_from(const YamlReader& yaml, const YAML::Node& node,
                                         const std::string& what) {
  if (node.IsScalar()) {
    const std::string& name = node.Scalar();
    if (name == "x" || name == "+x") return Eigen::Vector3d(Eigen::Vector3d::UnitX());
    if (name == "y" || name == "+y") return Eigen::Vector3d(Eigen::Vector3d::UnitY());
    if (name == "z" || name == "+z") return Eigen::Vector3d(Eigen::Vector3d::UnitZ());
    if (name == "-x") return Eigen::Vector3d(-Eigen::Vector3d::UnitX());
    if (name == "-y") return Eigen::Vector3d(-Eigen::Vector3d::UnitY());
    if (name == "-z") return Eigen::Vector3d(-Eigen::Vector3d::UnitZ());
    return yaml.error(node, what, "'" + name + "' is not an axis (x, y, z, -x, ... or [x, y, z])");
  }
  const auto v = yaml.vector3(node, what);
  if (!v) return v.error();
  if (v->norm() < 1e-9) return yaml.error(node, what, "must not be the zero vector");
  return Eigen::Vector3d(v->normalized());
}

}  // namespace tetra::sim
