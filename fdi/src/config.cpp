#include "tetra/fdi/config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <variant>
#include <vector>

#include "config_keys.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/yaml_reader.hpp"

namespace tetra::fdi {

namespace {

// Sets one key from its YAML value (the range is validate()'s).
Status set_pipeline_key(PipelineConfig& config, const ConfigKey& key, const YamlReader& yaml,
                        const YAML::Node& name, const YAML::Node& value) {
  const std::string what = std::string("pipeline.") + key.name;
  if (const auto* q = std::get_if<Quaternion PipelineConfig::*>(&key.field)) {
    if (!value.IsSequence() || value.size() != 4) return yaml.error(name, what, "expected [w, x, y, z]");
    double c[4] = {};
    for (std::size_t k = 0; k < 4; ++k) {
      const auto v = yaml.number(value[k], what + "[" + std::to_string(k) + "]");
      if (!v) return v.error();
      c[k] = *v;
    }
    config.*(*q) = from_wxyz(c[0], c[1], c[2], c[3]);
    return ok_status();
  }
  if (!value.IsScalar()) return yaml.error(name, what, "expected a scalar");
  if (const auto* b = std::get_if<bool PipelineConfig::*>(&key.field)) {
    const std::string& text = value.Scalar();
    if (text != "true" && text != "false")
      return yaml.error(value, what, "'" + text + "' is not true or false");
    config.*(*b) = text == "true";
    return ok_status();
  }
  const auto v = yaml.number(value, what);
  if (!v) return v.error();
  if (const auto* d = std::get_if<double PipelineConfig::*>(&key.field)) {
    config.*(*d) = *v;
  } else {
    config.*std::get<std::optional<double> PipelineConfig::*>(key.field) = *v;
  }
  return ok_status();
}

// A constant's value and unit as the listing and the refusal state them: "30 samples", "0.05".
std::string constant_text(const DesignConstant& constant) {
  std::string out;
  append_double(out, constant.value);
  if (std::string(constant.unit) != "-") out += std::string(" ") + constant.unit;
  return out;
}

// Columns of UTF-8 text (a unit such as "deg/√s" has more bytes than columns).
std::size_t display_width(const std::string& text) {
  std::size_t n = 0;
  for (const char ch : text) n += (static_cast<unsigned char>(ch) & 0xC0U) != 0x80U;
  return n;
}

// Appends `text` as lines of at most 106 columns, the first after `first`, the others after `next`.
void append_wrapped(std::string& out, const std::string& text, const std::string& first,
                    const std::string& next) {
  constexpr std::size_t kWidth = 106;
  std::string line = first;
  bool empty = true;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!empty && display_width(line) + 1 + display_width(word) > kWidth) {
      out += line + '\n';
      line = next;
      empty = true;
    }
    if (!empty) line += ' ';
    line += word;
    empty = false;
    start = end + 1;
  }
  out += line + '\n';
}

}  // namespace

Result<PipelineConfig> pipeline_config_from_yaml(const YAML::Node& node, const std::string& source) {
  PipelineConfig config;
  if (!node || node.IsNull()) return config;
  const YamlReader yaml{source};
  std::vector<std::string> allowed;
  for (const auto& key : config_keys()) allowed.emplace_back(key.name);
  std::vector<std::string> names = allowed;  // a constant's name is known, then refused by name
  for (const auto& constant : design_constants()) names.emplace_back(constant.name);
  if (Status st = yaml.check_keys(node, names, "pipeline"); !st) {
    return yaml.check_keys(node, allowed, "pipeline").error();  // the message lists the keys alone
  }
  try {
    for (const auto& kv : node) {
      const std::string name = kv.first.Scalar();
      for (const auto& constant : design_constants()) {
        if (name != constant.name) continue;
        return yaml.error(kv.first, "pipeline." + name,
                          "a fixed design constant (" + constant_text(constant) +
                              "), not a key: it cannot be set (docs/fdi.md, \"Fixed design constants\")");
      }
      for (const auto& key : config_keys()) {
        if (name != key.name) continue;
        if (Status st = set_pipeline_key(config, key, yaml, kv.first, kv.second); !st) return st.error();
      }
    }
  } catch (const YAML::Exception& e) {
    return yaml.error(e, "pipeline");
  }
  if (auto st = validate(config); !st) return bad_input(source + ": " + st.error().message);
  return config;
}

Result<PipelineConfig> parse_pipeline_config(const std::string& yaml_text, const std::string& source) {
  const YamlReader yaml{source};
  auto loaded = yaml.load(yaml_text);
  if (!loaded) return loaded.error();
  const YAML::Node root = *loaded;
  if (!root || root.IsNull()) return PipelineConfig{};
  if (!root.IsMap()) return bad_input(source + ": expected a mapping with a 'pipeline:' key");
  if (Status st = yaml.check_keys(root, {"pipeline"}, ""); !st) return st.error();
  return pipeline_config_from_yaml(root["pipeline"], source);
}

Result<PipelineConfig> read_pipeline_config(const std::string& path) {
  auto text = read_input(path, kMaxYamlBytes);
  if (!text) return text.error();
  return parse_pipeline_config(*text, path);
}

Status validate(const PipelineConfig& c) {
  for (const auto& key : config_keys()) {
    double v = 0.0;
    if (const auto* d = std::get_if<double PipelineConfig::*>(&key.field)) {
      v = c.*(*d);
    } else if (const auto* o = std::get_if<std::optional<double> PipelineConfig::*>(&key.field)) {
      if (!(c.*(*o))) continue;  // not set
      v = *(c.*(*o));
    } else {
      continue;  // a flag; the quaternion below
    }
    if (!within_range(key, v)) {
      std::string value;
      append_double(value, v);
      return bad_input(std::string("pipeline.") + key.name + ": must be " + range_text(key) + ", got " +
                       value);
    }
  }
  // Rules a row cannot state, each checked here:
  // - the initial attitude is a rotation: its norm within 1e-3 of 1 (a typo in a component is an error,
  //   never normalized away).
  const double qn = c.initial_q_RB.norm();
  if (!std::isfinite(qn) || std::abs(qn - 1.0) > 1e-3) {
    return bad_input("pipeline.initial_q_wxyz: must be a unit quaternion (norm within 1e-3 of 1)");
  }
  return ok_status();
}

std::string describe(const PipelineConfig& c) {
  std::string out;
  for (const auto& key : config_keys()) {
    out += key.name;
    out += ": ";
    out += value_text(c, key);
    out += '\n';
  }
  return out;
}

std::string describe_keys() {
  const PipelineConfig defaults;
  std::size_t w_name = 3, w_unit = 4, w_range = 5, w_default = 7;
  for (const auto& key : config_keys()) {
    w_name = std::max(w_name, std::string(key.name).size());
    w_unit = std::max(w_unit, display_width(key.unit));
    w_range = std::max(w_range, range_text(key).size());
    w_default = std::max(w_default, value_text(defaults, key).size());
  }
  std::string out;
  auto row = [&](const std::string& name, const std::string& unit, const std::string& range,
                 const std::string& fallback, const std::string& description) {
    out += name + std::string(w_name + 2 - name.size(), ' ');
    out += unit + std::string(w_unit + 2 - display_width(unit), ' ');
    out += range + std::string(w_range + 2 - range.size(), ' ');
    out += fallback + std::string(w_default + 2 - fallback.size(), ' ');
    out += description + '\n';
  };
  row("key", "unit", "range", "default", "meaning");
  for (const auto& key : config_keys())
    row(key.name, key.unit, range_text(key), value_text(defaults, key), key.description);

  // The fixed design constants: not keys (a `pipeline:` map that sets one is refused).
  std::size_t w_constant = 8, w_value = 5;
  w_unit = 4;
  for (const auto& constant : design_constants()) {
    w_constant = std::max(w_constant, std::string(constant.name).size());
    w_unit = std::max(w_unit, display_width(constant.unit));
    std::string value;
    append_double(value, constant.value);
    w_value = std::max(w_value, value.size());
  }
  out += "\nfixed design constants (not keys: a configuration that sets one is refused)\n";
  auto constant_row = [&](const std::string& name, const std::string& unit, const std::string& value,
                          const std::string& meaning) {
    out += name + std::string(w_constant + 2 - name.size(), ' ');
    out += unit + std::string(w_unit + 2 - display_width(unit), ' ');
    out += value + std::string(w_value + 2 - value.size(), ' ');
    out += meaning + '\n';
  };
  constant_row("constant", "unit", "value", "meaning");
  for (const auto& constant : design_constants()) {
    std::string value;
    append_double(value, constant.value);
    constant_row(constant.name, constant.unit, value, constant.description);
  }
  return out;
}

std::string example_config() {
  const PipelineConfig defaults;
  std::string out =
      "# Fusion pipeline configuration, as tetra replay reads it: every key of the `pipeline:` map at its\n"
      "# default, each after its [unit, range] and meaning (tetra replay prints this file and the same as a\n"
      "# table). A service's configuration (tetra fusion) takes the same map beside its own keys. How the\n"
      "# thresholds follow from the keys: docs/fdi.md, \"Configuration\".\n"
      "pipeline:\n";
  for (const auto& key : config_keys()) {
    std::string head = "[";
    if (std::string(key.unit) != "-") head += std::string(key.unit) + ", ";
    head += range_text(key) + "] " + key.description;
    append_wrapped(out, head, "  # ", "  #   ");
    const std::string value = value_text(defaults, key);
    // A key without a default (latitude_deg) stays commented out: absent is its default.
    out += std::string(value == "none" ? "  # " : "  ") + key.name + ": " + value + '\n';
  }
  return out;
}

}  // namespace tetra::fdi
