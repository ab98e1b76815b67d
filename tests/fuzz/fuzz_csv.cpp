// libFuzzer target: the CSV table reader (core/csv.hpp) on arbitrary bytes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/core/csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto table = tetra::parse_csv(text, "fuzz.csv");
  if (!table) {
    tetra::fuzz::check_error_message(table.error());
    return 0;
  }
  const std::size_t n_cols = table->column_count();
  TETRA_FUZZ_CHECK(n_cols > 0);
  TETRA_FUZZ_CHECK(table->cells.size() == table->rows * n_cols);
  TETRA_FUZZ_CHECK(table->empty.size() == table->rows * n_cols);
  TETRA_FUZZ_CHECK(table->lines.size() == table->rows);
  for (std::size_t r = 0; r < table->rows; ++r) {
    TETRA_FUZZ_CHECK(table->lines[r] > table->header_line);
    for (std::size_t c = 0; c < n_cols; ++c) {
      // An empty cell reads as NaN.
      if (table->is_empty(r, c)) TETRA_FUZZ_CHECK(std::isnan(table->cell(r, c)));
    }
  }
  for (std::size_t c = 0; c < n_cols; ++c) {
    TETRA_FUZZ_CHECK(table->find_column(table->columns[c]).has_value());
  }
  if (table->rows > 0) (void)table->where(table->rows - 1, n_cols - 1);
  for (const auto& kv : table->metadata) (void)table->meta(kv.first);
  return 0;
}
