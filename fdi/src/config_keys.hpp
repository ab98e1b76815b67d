#pragma once
// The keys of the `pipeline:` map, each declared once (config_keys.cpp): name, member, unit, range,
// description; the default is read from a default-constructed PipelineConfig. Parsing, validate(),
// describe(), describe_keys() and example_config() (config.cpp) are driven by this table. Its second
// section, the fixed design constants (name, unit, value, meaning; the value is design::'s), is listed by
// describe_keys() and refused in a `pipeline:` map.

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "tetra/fdi/config.hpp"

namespace tetra::fdi {

//! The member a key sets. `initial_q_wxyz` is a quaternion written [w, x, y, z]; `latitude_deg` is optional.
using ConfigField = std::variant<double PipelineConfig::*, bool PipelineConfig::*,
                                 std::optional<double> PipelineConfig::*, Quaternion PipelineConfig::*>;

//! One end of a key's range: none (only a finite value is required), open (the bound itself is refused)
//! or closed (the bound is allowed).
struct ConfigLimit {
  enum class Edge { kNone, kOpen, kClosed };
  Edge edge = Edge::kNone;
  double value = 0.0;
};

struct ConfigKey {
  const char* name;
  ConfigField field;
  const char* unit;  //!< as shown to users: "deg/s", "s", "epochs", "-" (none)
  ConfigLimit min;
  ConfigLimit max;
  const char* description;  //!< one line; where a key serves more than one test, each is named
};

//! Every key of the `pipeline:` map, in the order describe() and the example file list them.
const std::vector<ConfigKey>& config_keys();

//! A fixed design constant (config.hpp, namespace design): not a key; a `pipeline:` map that sets it is
//! refused.
struct DesignConstant {
  const char* name;  //!< as in namespace design
  double value;      //!< design::<name>
  const char* unit;
  const char* description;  //!< one line; where it serves more than one test, each is named
};

//! Every fixed design constant, in the order describe_keys() lists them.
const std::vector<DesignConstant>& design_constants();

//! The range as users read it: "> 0", ">= 10", "in (0, 0.5)", "in [0, 10]"; "true or false" for a flag,
//! "unit norm" for the quaternion, "any" when only a finite value is required.
std::string range_text(const ConfigKey& key);
//! Whether `value` (finite or not) is within the key's range.
bool within_range(const ConfigKey& key, double value);
//! The key's value in `config` as describe() prints it: a number, true/false, [w, x, y, z] or "none".
std::string value_text(const PipelineConfig& config, const ConfigKey& key);

}  // namespace tetra::fdi
