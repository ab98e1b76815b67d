#include "tetra/core/yaml_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>
#include <vector>

#include "tetra/core/csv.hpp"
#include "tetra/core/json.hpp"

namespace tetra {

std::string YamlReader::at(const YAML::Node& node) const {
  const auto mark = node.Mark();
  if (mark.line < 0) return source_ + ": ";
  return source_ + ":" + std::to_string(mark.line + 1) + ": ";
}

Error YamlReader::error(const YAML::Node& node, const std::string& what, const std::string& message) const {
  return bad_input(at(node) + (what.empty() ? "" : what + ": ") + message);
}

Error YamlReader::error(const YAML::Exception& e, const std::string& what) const {
  const int line = e.mark.line < 0 ? 0 : e.mark.line + 1;
  const bool conversion = e.msg.rfind("bad conversion", 0) == 0;
  return bad_input(source_ + ":" + std::to_string(line) + ": " + (what.empty() ? "" : what + ": ") +
                   (conversion ? "a value of the wrong type (bad conversion)" : e.msg));
}

namespace {

// "a.b[2]" path of a key below `what`.
std::string key_path(const std::string& what, const std::string& key) {
  return what.empty() ? key : what + "." + key;
}

}  // namespace

Status YamlReader::check_unique_keys(const YAML::Node& node, const std::string& what) const {
  std::size_t budget = kMaxYamlNodes;
  return check_unique_keys(node, what, budget);
}

Status YamlReader::check_unique_keys(const YAML::Node& node, const std::string& what,
                                     std::size_t& budget) const {
  // Aliases make a small text a huge tree ("a billion laughs"): the walk is bounded, like the file.
  if (budget == 0)
    return error(node, what, "more than " + std::to_string(kMaxYamlNodes) + " nodes (aliases?)");
  --budget;
  if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      if (Status st = check_unique_keys(node[i], what + "[" + std::to_string(i) + "]", budget); !st)
        return st;
    }
  } else if (node.IsMap()) {
    std::vector<std::string> seen;
    for (const auto& kv : node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      for (const auto& s : seen) {
        if (s == key) return error(kv.first, what, "key '" + key + "' appears twice");
      }
      seen.push_back(key);
      if (Status st = check_unique_keys(kv.second, key_path(what, key), budget); !st) return st;
    }
  }
  return ok_status();
}

namespace {

// 1-based line of a second document in `text` (a "---" line after content, or content after a "..." line),
// or 0. Found in the text because yaml-cpp 0.7's LoadAll never returns on some malformed input (a lone ",").
int second_document_line(const std::string& text) {
  bool content = false;
  bool ended = false;
  int line_no = 0;
  for (std::size_t begin = 0; begin < text.size();) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    const std::string_view line(text.data() + begin, end - begin);
    begin = end + 1;
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#' || line[0] == '%') continue;
    const bool marker = line.substr(0, 3) == "---" && (line.size() == 3 || line[3] == ' ' || line[3] == '\r');
    const bool end_marker =
        line.substr(0, 3) == "..." && (line.size() == 3 || line[3] == ' ' || line[3] == '\r');
    if ((marker && content) || (ended && !end_marker)) return line_no;
    if (end_marker) {
      ended = content;
      continue;
    }
    if (!marker || line.find_first_not_of(" \t\r", 3) != std::string_view::npos) content = true;
  }
  return 0;
}

}  // namespace

Result<YAML::Node> YamlReader::load(const std::string& text) const {
  if (const int line = second_document_line(text); line > 0) {
    return bad_input(source_ + ":" + std::to_string(line) +
                     ": a second YAML document ('---'): a file holds exactly one");
  }
  try {
    YAML::Node doc = YAML::Load(text);
    if (Status st = check_unique_keys(doc, ""); !st) return st.error();
    return doc;
  } catch (const YAML::Exception& e) {
    return error(e, "");
  }
}

Result<std::string> YamlReader::text(const YAML::Node& node, const std::string& what) const {
  if (!node.IsScalar()) return error(node, what, "expected a text value");
  if (!is_valid_utf8(node.Scalar())) return error(node, what, "expected UTF-8 text");
  return node.Scalar();
}

Result<std::string> YamlReader::optional_text(const YAML::Node& parent, const std::string& key,
                                              const std::string& what) const {
  const YAML::Node node = parent[key];
  if (!node || node.IsNull()) return std::string();
  return text(node, child(what, key));
}

std::string YamlReader::child(const std::string& what, const std::string& key) {
  return what.empty() ? key : what + "." + key;
}

Status YamlReader::check_keys(const YAML::Node& map, const std::vector<std::string>& allowed,
                              const std::string& what) const {
  if (!map.IsMap()) return error(map, what, "expected a mapping");
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) return error(kv.first, what, "keys must be plain names");
    const std::string& key = kv.first.Scalar();
    bool known = false;
    for (const auto& a : allowed) known = known || a == key;
    if (!known) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      return error(kv.first, what, "unknown key '" + key + "' (allowed: " + list + ")");
    }
  }
  return ok_status();
}

Result<double> YamlReader::number(const YAML::Node& node, const std::string& what) const {
  double v = 0.0;
  if (!node.IsScalar() || !parse_number(node.Scalar(), v)) {
    return error(node, what,
                 "'" + (node.IsScalar() ? node.Scalar() : std::string("?")) + "' is not a number");
  }
  if (!std::isfinite(v)) return error(node, what, "must be finite");
  return v;
}

Result<double> YamlReader::required_number(const YAML::Node& parent, const std::string& key,
                                           const std::string& what) const {
  const YAML::Node node = parent[key];
  if (!node) return error(parent, what, "missing key '" + key + "'");
  return number(node, child(what, key));
}

Result<std::optional<double>> YamlReader::optional_number(const YAML::Node& parent, const std::string& key,
                                                          const std::string& what) const {
  const YAML::Node node = parent[key];
  if (!node || node.IsNull()) return std::optional<double>{};
  auto v = number(node, child(what, key));
  if (!v) return v.error();
  return std::optional<double>{*v};
}

namespace {

// The whole scalar as a T, or nullopt (from_chars: no blanks, no '+', no hexadecimal, no fraction).
template <class T>
std::optional<T> whole_scalar(const YAML::Node& node) {
  if (!node.IsScalar()) return std::nullopt;
  const std::string& text = node.Scalar();
  T value{};
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size()) return std::nullopt;
  return value;
}

// The value quoted for a message, at most 40 characters of it.
std::string scalar_text(const YAML::Node& node) {
  if (!node.IsScalar()) return "a list or a mapping";
  const std::string& text = node.Scalar();
  return "'" + (text.size() > 40 ? text.substr(0, 40) + "..." : text) + "'";
}

}  // namespace

Result<std::int64_t> YamlReader::integer(const YAML::Node& node, const std::string& what, std::int64_t min,
                                         std::int64_t max) const {
  const auto v = whole_scalar<std::int64_t>(node);
  if (!v || *v < min || *v > max) {
    return error(node, what,
                 "expected a whole number from " + std::to_string(min) + " to " + std::to_string(max) +
                     ", got " + scalar_text(node));
  }
  return *v;
}

Result<std::uint64_t> YamlReader::unsigned_integer(const YAML::Node& node, const std::string& what) const {
  const auto v = whole_scalar<std::uint64_t>(node);
  if (!v) {
    return error(
        node, what,
        "expected a whole number from 0 to " + std::to_string(UINT64_MAX) + ", got " + scalar_text(node));
  }
  return *v;
}

Result<bool> YamlReader::boolean(const YAML::Node& node, const std::string& what) const {
  if (node.IsScalar() && (node.Scalar() == "true" || node.Scalar() == "false"))
    return node.Scalar() == "true";
  return error(node, what, "expected true or false, got " + scalar_text(node));
}

Result<Eigen::Vector3d> YamlReader::vector3(const YAML::Node& node, const std::string& what) const {
  if (!node.IsSequence() || node.size() != 3) return error(node, what, "expected [x, y, z]");
  Eigen::Vector3d v;
  for (std::size_t i = 0; i < 3; ++i) {
    auto c = number(node[i], what + "[" + std::to_string(i) + "]");
    if (!c) return c.error();
    v[static_cast<Eigen::Index>(i)] = *c;
  }
  return v;
}

Result<Eigen::Vector3d> YamlReader::required_vector3(const YAML::Node& parent, const std::string& key,
                                                     const std::string& what) const {
  const YAML::Node node = parent[key];
  if (!node) return error(parent, what, "missing key '" + key + "'");
  return vector3(node, child(what, key));
}

}  // namespace tetra
