// libFuzzer target: `tetra allan --taus SPEC` (parse_tau_spec) on arbitrary bytes; an accepted spec
// gives averaging factors 1 ≤ m ≤ samples/2, increasing, or an error.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/core/allan.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto spec = tetra::allan::parse_tau_spec(text);
  if (!spec) {
    tetra::fuzz::check_error_message(spec.error());
    return 0;
  }
  if (spec->spacing == tetra::allan::TauSpacing::kAll)
    return 0;  // O(n²) by design; its limit is tested elsewhere
  constexpr std::size_t kSamples = 100000;
  const auto factors = tetra::allan::averaging_factors(*spec, kSamples, 0.1);
  if (!factors) {
    tetra::fuzz::check_error_message(factors.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(!factors->empty());
  for (std::size_t i = 0; i < factors->size(); ++i) {
    TETRA_FUZZ_CHECK((*factors)[i] >= 1 && static_cast<std::size_t>((*factors)[i]) <= kSamples / 2);
    if (i > 0) TETRA_FUZZ_CHECK((*factors)[i] > (*factors)[i - 1]);
  }
  return 0;
}
