#include "tetra/service/security_profile.hpp"

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "tetra/core/input_files.hpp"
#include "tetra/core/yaml_reader.hpp"

namespace tetra::service {

namespace {

//! The keys in file order of make_pki.sh, with the member each one fills.
using Field = std::pair<const char*, std::string SecurityProfile::*>;
constexpr std::array<Field, 6> kFields = {{
    {"identity_ca", &SecurityProfile::identity_ca},
    {"identity_certificate", &SecurityProfile::identity_certificate},
    {"private_key", &SecurityProfile::private_key},
    {"permissions_ca", &SecurityProfile::permissions_ca},
    {"governance", &SecurityProfile::governance},
    {"permissions", &SecurityProfile::permissions},
}};

}  // namespace

Result<SecurityProfile> parse_security_profile(const std::string& yaml_text, const std::string& source,
                                               const std::string& base_dir) {
  const YamlReader reader(source);
  auto loaded = reader.load(yaml_text);
  if (!loaded) return loaded.error();
  const YAML::Node root = std::move(loaded).value();
  if (!root.IsMap()) return bad_input(source + ": expected a YAML map of the six security documents");
  std::vector<std::string> allowed;
  for (const auto& f : kFields) allowed.emplace_back(f.first);
  if (auto keys = reader.check_keys(root, allowed, ""); !keys) return keys.error();
  SecurityProfile profile;
  profile.source = source;
  for (const auto& item : root) {
    const std::string& key = item.first.Scalar();
    const Field* field = nullptr;  // found: check_keys allowed only these names
    for (const auto& f : kFields) {
      if (key == f.first) field = &f;
    }
    if (!item.second.IsScalar() || item.second.Scalar().empty()) {
      return reader.error(item.second, key, "must be a file name");
    }
    std::filesystem::path path(item.second.Scalar());
    if (path.is_relative() && !base_dir.empty()) path = std::filesystem::path(base_dir) / path;
    profile.*(field->second) = path.string();
  }
  for (const auto& [key, member] : kFields) {
    if ((profile.*member).empty()) return bad_input(source + ": missing key '" + key + "'");
  }
  return profile;
}

Result<SecurityProfile> read_security_profile(const std::string& path) {
  auto text = read_input(path, kMaxYamlBytes);
  if (!text) return text.error();
  auto profile = parse_security_profile(*text, path, std::filesystem::path(path).parent_path().string());
  if (!profile) return profile;
  for (const auto& [key, member] : kFields) {
    const std::string& file = profile.value().*member;
    if (!std::ifstream(file)) return bad_input(path + ": " + key + ": cannot read '" + file + "'");
  }
  return profile;
}

std::string describe(const SecurityProfile& profile) {
  std::string out = "security (" + profile.source + "):";
  for (const auto& [key, member] : kFields) out += std::string("\n  ") + key + ": " + profile.*member;
  return out;
}

}  // namespace tetra::service
