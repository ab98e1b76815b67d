// libFuzzer target: the TDMS reader (core/tdms.hpp, docs/formats.md "TDMS") on arbitrary bytes, then the
// table a gyro log or turntable log is read from. A parse either fails with one line naming the file and
// the segment, or gives channels and a table that agree with each other; never a crash or a huge allocation
// (libFuzzer's -rss_limit_mb catches the latter).
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "tetra/core/tdms.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = tetra::parse_tdms(std::span<const std::uint8_t>(data, size), "fuzz.tdms");
  if (!file) {
    tetra::fuzz::check_error_message(file.error());
    TETRA_FUZZ_CHECK(file.error().message.rfind("fuzz.tdms: ", 0) == 0);
    return 0;
  }
  for (const auto& ch : file->channels) {
    TETRA_FUZZ_CHECK(ch.numeric ? ch.values.size() == ch.value_count : ch.values.empty());
    TETRA_FUZZ_CHECK(ch.values.size() <= size);  // at most one value per byte of the file
  }
  const auto table = tetra::tdms_to_table(*file, {});
  if (!table) {
    tetra::fuzz::check_error_message(table.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(table->cells.size() == table->rows * table->column_count());
  TETRA_FUZZ_CHECK(table->empty.size() == table->cells.size());
  TETRA_FUZZ_CHECK(table->lines.size() == table->rows);
  TETRA_FUZZ_CHECK(table->metadata.size() == file->properties.size());
  return 0;
}
