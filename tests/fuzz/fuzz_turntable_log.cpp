// libFuzzer target: the turntable log reader (core/turntable_log.hpp, docs/interfaces.md §2.1) on arbitrary
// bytes, and the writer's round trip: what the reader accepts, format_turntable_log writes back and
// the reader reads again to the same numbers, bit for bit.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/core/turntable_log.hpp"

namespace {

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto log = tetra::parse_turntable_log(text, "fuzz.csv");
  if (!log) {
    tetra::fuzz::check_error_message(log.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(log->gyro_count >= 3);
  const std::size_t rows = log->rows();
  TETRA_FUZZ_CHECK(log->sequence.size() == rows && log->inner_deg.size() == rows &&
                   log->outer_deg.size() == rows);
  TETRA_FUZZ_CHECK(log->g_V.size() == rows * static_cast<std::size_t>(log->gyro_count));
  for (const int s : log->sequence) TETRA_FUZZ_CHECK(s >= 1);

  const std::string again_text = tetra::format_turntable_log(*log);
  const auto again = tetra::parse_turntable_log(again_text, "fuzz-again.csv");
  if (!again) {
    std::fprintf(stderr, "round trip rejected: %s\n", again.error().message.c_str());
    TETRA_FUZZ_CHECK(again.ok());
  }
  TETRA_FUZZ_CHECK(again->gyro_count == log->gyro_count);
  TETRA_FUZZ_CHECK(again->sequence == log->sequence);
  TETRA_FUZZ_CHECK(same_bits(again->time_s, log->time_s));
  TETRA_FUZZ_CHECK(same_bits(again->inner_deg, log->inner_deg));
  TETRA_FUZZ_CHECK(same_bits(again->outer_deg, log->outer_deg));
  TETRA_FUZZ_CHECK(same_bits(again->g_V, log->g_V));
  return 0;
}
