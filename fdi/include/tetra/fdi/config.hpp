#pragma once
// Pipeline configuration: a struct with in-class defaults, validated once, echoed at start-up.
// Read from the `pipeline:` map of a YAML file (replay --config, fusion --config).

#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"

namespace tetra::fdi {

struct PipelineConfig {
  // Fields are added by the pipeline implementation; each with its unit and a default.
  std::optional<double> latitude_deg;                   //!< [deg] ground-test mode: remove Earth rate
  Quaternion initial_q_RB = Quaternion::Identity();     //!< initial attitude (relative to L in ground mode)
};

//! Parses a `pipeline:` YAML map (unknown keys are errors naming the line); `source` names the file.
Result<PipelineConfig> pipeline_config_from_yaml(const YAML::Node& node, const std::string& source);
//! Validates ranges; error names the field.
Status validate(const PipelineConfig& config);
//! Multi-line "key: value" echo of every field, for start-up logs.
std::string describe(const PipelineConfig& config);

}  // namespace tetra::fdi
