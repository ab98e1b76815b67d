#include "tetra/service/security_profile.hpp"

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include <yaml-cpp/yaml.h>

namespace tetra::service {

namespace {

std::string where(const std::string& source, const YAML::Node& node) {
  const auto mark = node.Mark();
  if (mark.line < 0) return source + ": ";
  return source + ":" + std::to_string(mark.line + 1) + ": ";
}

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
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return bad_input(source + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) return bad_input(source + ": expected a YAML map of the six security documents");
  SecurityProfile profile;
  profile.source = source;
  try {
    for (const auto& item : root) {
      const auto key = item.first.as<std::string>();
      const Field* field = nullptr;
      for (const auto& f : kFields) {
        if (key == f.first) field = &f;
      }
      if (field == nullptr) {
        return bad_input(where(source, item.first) + "unknown key '" + key +
                         "' (allowed: identity_ca, identity_certificate, private_key, permissions_ca, "
                         "governance, permissions)");
      }
      if (!item.second.IsScalar() || item.second.Scalar().empty()) {
        return bad_input(where(source, item.second) + key + " must be a file name");
      }
      std::filesystem::path path(item.second.Scalar());
      if (path.is_relative() && !base_dir.empty()) path = std::filesystem::path(base_dir) / path;
      profile.*(field->second) = path.string();
    }
  } catch (const YAML::Exception& e) {
    return bad_input(source + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  for (const auto& [key, member] : kFields) {
    if ((profile.*member).empty()) return bad_input(source + ": missing key '" + key + "'");
  }
  return profile;
}

Result<SecurityProfile> read_security_profile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return bad_input(path + ": cannot open the DDS Security profile");
  std::stringstream text;
  text << in.rdbuf();
  auto profile = parse_security_profile(text.str(), path, std::filesystem::path(path).parent_path().string());
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
