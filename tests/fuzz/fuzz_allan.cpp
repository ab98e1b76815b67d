// libFuzzer target: what `tetra allan` does with a file — the gyro log reader, the sampling grid, the
// overlapping Allan deviation and the IEEE 952 fit — on arbitrary bytes, and the report writers.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/core/allan.hpp"
#include "tetra/core/gyro_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto log = tetra::parse_gyro_log(text, "fuzz.csv");
  if (!log) return 0;  // the reader has its own target
  const auto analysis = tetra::allan::analyze_gyro_log(*log, tetra::allan::LogAllanOptions{});
  if (!analysis) {
    tetra::fuzz::check_error_message(analysis.error());
    return 0;
  }
  for (const auto& gyro : analysis->gyros) {
    for (const auto& p : gyro.result.points) {
      // A deviation is never negative; NaN would poison the fit and the reports.
      TETRA_FUZZ_CHECK(!(p.adev < 0.0));
      TETRA_FUZZ_CHECK(p.tau_s > 0.0);
    }
  }
  (void)tetra::allan::format_csv(*analysis);
  (void)tetra::allan::format_json(*analysis);
  (void)tetra::allan::format_table(*analysis);
  return 0;
}
