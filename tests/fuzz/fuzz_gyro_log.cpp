// libFuzzer target: the gyro log reader (core/gyro_log.hpp, docs/interfaces.md §2.2) on arbitrary bytes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/core/gyro_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto log = tetra::parse_gyro_log(text, "fuzz.csv");
  if (!log) {
    tetra::fuzz::check_error_message(log.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(log->gyro_count >= 1);
  const std::size_t n = static_cast<std::size_t>(log->gyro_count);
  const std::size_t epochs = log->epochs();
  TETRA_FUZZ_CHECK(log->values.size() == epochs * n);
  TETRA_FUZZ_CHECK(log->present.size() == epochs * n);
  TETRA_FUZZ_CHECK(log->lines.size() == epochs);
  if (log->has_reference) {
    TETRA_FUZZ_CHECK(log->reference_wxyz.size() == epochs);
    TETRA_FUZZ_CHECK(log->reference_present.size() == epochs);
  }
  for (std::size_t e = 0; e < epochs; ++e) {
    for (int g = 0; g < log->gyro_count; ++g) {
      // "No sample delivered" must never carry a number a consumer could mistake for a sample.
      if (!log->is_present(e, g)) TETRA_FUZZ_CHECK(std::isnan(log->value(e, g)));
    }
  }
  return 0;
}
