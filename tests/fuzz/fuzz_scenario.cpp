// libFuzzer target: the simulator's scenario YAML reader (sim/scenario.hpp) on arbitrary bytes.
// An accepted scenario goes through validate_scenario, which must answer without crashing.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "tetra/sim/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // `unit:` paths resolve against a directory that does not exist: a relative path is a read error.
  const auto scenario = tetra::sim::parse_scenario(text, "fuzz.yaml", "/nonexistent-tetra-fuzz");
  if (!scenario) {
    tetra::fuzz::check_error_message(scenario.error());
    return 0;
  }
  const auto status = tetra::sim::validate_scenario(*scenario);
  if (!status) tetra::fuzz::check_error_message(status.error());
  return 0;
}
