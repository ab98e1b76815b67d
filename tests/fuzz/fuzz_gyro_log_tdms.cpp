// libFuzzer target: the TDMS reader (core/tdms.hpp, docs/formats.md "TDMS") on arbitrary bytes, then the
// table a gyro log or turntable log is read from. A parse either fails with one line naming the file and
// the segment, or gives channels and a table that agree with each other; never a crash or a huge allocation
// (libFuzzer's -rss_limit_mb catches the latter).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "fuzz_check.hpp"
#include "tetra/core/tdms.hpp"

// The two-pass reader (tdms_image_to_table: counts, then each column decoded into its cells) ends as
// parse_tdms + tdms_to_table did: the same error, or the same cells bit for bit.
void check_two_passes(std::span<const std::uint8_t> bytes, const tetra::Result<tetra::CsvTable>& one_pass) {
  const auto two = tetra::tdms_image_to_table(bytes, "fuzz.tdms", {});
  TETRA_FUZZ_CHECK(static_cast<bool>(two) == static_cast<bool>(one_pass));
  if (!two) {
    TETRA_FUZZ_CHECK(two.error().message == one_pass.error().message);
    return;
  }
  TETRA_FUZZ_CHECK(two->columns == one_pass->columns && two->rows == one_pass->rows);
  TETRA_FUZZ_CHECK(two->metadata == one_pass->metadata && two->lines == one_pass->lines);
  TETRA_FUZZ_CHECK(two->cells.size() == one_pass->cells.size());
  TETRA_FUZZ_CHECK(two->cells.empty() || std::memcmp(two->cells.data(), one_pass->cells.data(),
                                                     two->cells.size() * sizeof(double)) == 0);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  const auto file = tetra::parse_tdms(bytes, "fuzz.tdms");
  if (!file) {
    const auto two = tetra::tdms_image_to_table(bytes, "fuzz.tdms", {});
    TETRA_FUZZ_CHECK(!two && two.error().message == file.error().message);
    tetra::fuzz::check_error_message(file.error());
    TETRA_FUZZ_CHECK(file.error().message.rfind("fuzz.tdms: ", 0) == 0);
    return 0;
  }
  for (const auto& ch : file->channels) {
    TETRA_FUZZ_CHECK(ch.numeric ? ch.values.size() == ch.value_count : ch.values.empty());
    TETRA_FUZZ_CHECK(ch.values.size() <= size);  // at most one value per byte of the file
  }
  const auto table = tetra::tdms_to_table(*file, {});
  check_two_passes(bytes, table);
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
