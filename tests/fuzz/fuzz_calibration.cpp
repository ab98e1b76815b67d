// libFuzzer target: the calibration YAML reader (core/calibration_file.hpp, docs/interfaces.md §2.3) on
// arbitrary bytes, and the round trip: an accepted calibration is valid, and what
// format_calibration writes reads back to the same gyros.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "tetra/core/calibration_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto cal = tetra::parse_calibration(text, "fuzz.yaml");
  if (!cal) {
    tetra::fuzz::check_error_message(cal.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(cal->gyro_count() >= 3);
  TETRA_FUZZ_CHECK(tetra::validate_calibration(*cal, "fuzz.yaml").ok());

  const std::string again_text = tetra::format_calibration(*cal);
  const auto again = tetra::parse_calibration(again_text, "fuzz-again.yaml");
  if (!again) {
    std::fprintf(stderr, "round trip rejected: %s\n", again.error().message.c_str());
    TETRA_FUZZ_CHECK(again.ok());
  }
  TETRA_FUZZ_CHECK(again->gyro_count() == cal->gyro_count());
  TETRA_FUZZ_CHECK(again->unit == cal->unit);
  for (int i = 0; i < cal->gyro_count(); ++i) {
    const auto& a = cal->gyros[static_cast<std::size_t>(i)];
    const auto& b = again->gyros[static_cast<std::size_t>(i)];
    TETRA_FUZZ_CHECK(a.id == b.id);
    TETRA_FUZZ_CHECK(a.scale_factor_V_per_dps == b.scale_factor_V_per_dps);
    TETRA_FUZZ_CHECK(a.bias_V == b.bias_V);
  }
  return 0;
}
