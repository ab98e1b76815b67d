// libFuzzer target: the HDF5 gyro log reader (core/src/gyro_log_h5.cpp, docs/formats.md) on arbitrary
// bytes taken as an in-memory HDF5 file image. It runs in this process everything the reader runs
// (the checks made in the checking child process included) but the reading of variable-length string
// attributes, which only the child does (docs/formats.md, "HDF5 gyro log").
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "gyro_log_h5.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto log = tetra::read_gyro_log_h5_image(std::span<const std::uint8_t>(data, size), "fuzz.h5");
  if (!log) {
    tetra::fuzz::check_error_message(log.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(log->gyro_count >= 1);
  const auto n = static_cast<std::size_t>(log->gyro_count);
  const std::size_t epochs = log->epochs();
  TETRA_FUZZ_CHECK(log->values.size() == epochs * n);
  TETRA_FUZZ_CHECK(log->present.size() == epochs * n);
  for (const auto& c : log->comments) TETRA_FUZZ_CHECK(c.find('\n') == std::string::npos);
  for (std::size_t e = 0; e < epochs; ++e) {
    TETRA_FUZZ_CHECK(std::isfinite(log->time_s[e]));
    for (int g = 0; g < log->gyro_count; ++g) {
      if (!log->is_present(e, g)) TETRA_FUZZ_CHECK(std::isnan(log->value(e, g)));
    }
  }
  return 0;
}
