// libFuzzer target: the fault specification parser (sim/fault.hpp, docs/interfaces.md §2.7) on arbitrary
// bytes, and its round trip through format_fault_spec.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/sim/fault.hpp"

namespace {

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto fault = tetra::sim::parse_fault_spec(text);
  if (!fault) {
    tetra::fuzz::check_error_message(fault.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(fault->gyro >= 1);
  const std::string again_text = tetra::sim::format_fault_spec(*fault);
  const auto again = tetra::sim::parse_fault_spec(again_text);
  if (!again) {
    std::fprintf(stderr, "round trip rejected: %s\n", again.error().message.c_str());
    TETRA_FUZZ_CHECK(again.ok());
  }
  TETRA_FUZZ_CHECK(again->gyro == fault->gyro && again->kind == fault->kind);
  TETRA_FUZZ_CHECK(same_bits(again->at_s, fault->at_s));
  TETRA_FUZZ_CHECK(same_bits(again->size, fault->size));
  TETRA_FUZZ_CHECK(again->until_s.has_value() == fault->until_s.has_value());
  if (fault->until_s) TETRA_FUZZ_CHECK(same_bits(*again->until_s, *fault->until_s));
  return 0;
}
