#pragma once
// The checks of a turntable log's header and rows, shared by the whole-log readers (turntable_log.cpp)
// and the pass-by-pass reader (turntable_rows.cpp). Private to tetra::core.

#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "tetra/core/csv.hpp"
#include "tetra/core/result.hpp"

namespace tetra::turntable_detail {

//! The columns of a turntable log, found in its header.
struct Columns {
  std::size_t fixed[4] = {};  //!< sequence, time_s, inner_deg, outer_deg
  std::vector<std::size_t> gyro;
};

//! The columns named in the header of `t` (errors name the header line).
Result<Columns> find_columns(const CsvTable& t);

//! Checks row `r` of `t`: every cell a finite number, the sequence a positive integer, the time after
//! `previous_time_s` (none for the file's first row). Messages name the file, line and column.
Status check_row(const CsvTable& t, const Columns& c, std::size_t r, const double* previous_time_s);

//! An unnamed temporary binary file in $TMPDIR or /tmp, removed from its folder at once (freed when
//! closed); `what` names its use in messages.
Result<std::FILE*> open_temporary_file(const std::string& what);

//! Comment lines found in a block after the `header_entries` of the header (the whole file's order).
void append_block_metadata(const CsvTable& block, std::size_t header_entries, Metadata& metadata);

}  // namespace tetra::turntable_detail
