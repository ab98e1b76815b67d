// libFuzzer target: the pipeline configuration (`tetra replay --config`, the `pipeline:` map of the
// service's file) on arbitrary bytes: read, validated, then used to create a pipeline for the seed's
// unit. A configuration that validates must give a pipeline (or an error), never a crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include <yaml-cpp/yaml.h>

#include "fuzz_check.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/fdi/pipeline.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception&) {
    return 0;  // not YAML at all: the readers' own targets cover that path
  }
  if (!root.IsMap() || !root["pipeline"]) return 0;
  const auto config = tetra::fdi::pipeline_config_from_yaml(root["pipeline"], "fuzz.yaml");
  if (!config) {
    tetra::fuzz::check_error_message(config.error());
    return 0;
  }
  (void)tetra::fdi::describe(*config);
  const auto valid = tetra::fdi::validate(*config);
  if (!valid) {
    tetra::fuzz::check_error_message(valid.error());
    return 0;
  }
  auto pipeline = tetra::fdi::Pipeline::create(tetra::seed_as_built_unit(), *config);
  if (!pipeline) {
    tetra::fuzz::check_error_message(pipeline.error());
    return 0;
  }
  (void)pipeline->describe_thresholds();
  // One quiet epoch through the configured pipeline.
  tetra::fdi::Epoch epoch;
  epoch.stamp_ns = 1'000'000'000;
  for (const auto& g : tetra::seed_as_built_unit().gyros) {
    epoch.raw.push_back(config->raw_units_dps ? 0.0 : g.bias_V);
    epoch.present.push_back(1);
  }
  (void)pipeline->step(epoch);
  return 0;
}
