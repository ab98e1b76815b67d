// libFuzzer target: the line protocol of `tetra ingest` (core/sample_parser.hpp) on arbitrary bytes, fed in
// two pieces split where the first byte says (a stream may break a line anywhere). Every line is either
// samples of gyros 1..N with finite times or one refusal; never a crash; the split does not change the
// result.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_check.hpp"
#include "tetra/core/sample_parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int gyros = 1 + data[0] % 8;
  const std::span<const std::uint8_t> bytes(data + 1, size - 1);
  const std::size_t cut = bytes.empty() ? 0 : data[0] % bytes.size();
  tetra::LineProtocolParser whole(gyros);
  tetra::LineProtocolParser split(gyros);
  std::vector<tetra::RawGyroSample> a;
  std::vector<tetra::RawGyroSample> b;
  whole.feed(bytes, a);
  whole.flush(a);
  split.feed(bytes.subspan(0, cut), b);
  split.feed(bytes.subspan(cut), b);
  split.flush(b);
  TETRA_FUZZ_CHECK(a.size() == b.size());
  TETRA_FUZZ_CHECK(whole.malformed() == split.malformed() && whole.accepted() == split.accepted());
  for (std::size_t k = 0; k < a.size(); ++k) {
    TETRA_FUZZ_CHECK(a[k].gyro >= 1 && a[k].gyro <= gyros);
    TETRA_FUZZ_CHECK(std::isfinite(a[k].time_s));
    TETRA_FUZZ_CHECK(!std::isinf(a[k].raw));
    TETRA_FUZZ_CHECK(a[k].gyro == b[k].gyro && a[k].time_s == b[k].time_s);
  }
  if (whole.malformed() > 0) TETRA_FUZZ_CHECK(!whole.last_problem().empty());
  return 0;
}
