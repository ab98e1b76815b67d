#pragma once
// Text tables of docs/interfaces.md §2: UTF-8, '#' starts a comment line (metadata "# key=value" allowed, the
// value with %XX escapes for blanks, commas, '%' and control characters),
// the first non-comment line is a header, columns are matched by name. Every cell is parsed as a
// number; an empty cell is kept as "empty" (value NaN), "nan" as NaN. A malformed file is an Error
// naming the file, the line and the column — never a crash, never a silently skipped row.

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tetra/core/result.hpp"

namespace tetra {

//! "# key=value" metadata comments of a text file, in file order.
using Metadata = std::vector<std::pair<std::string, std::string>>;
//! The last value of `key` in `metadata` (a later line overrides an earlier one), or nullopt.
std::optional<std::string> last_meta(const Metadata& metadata, std::string_view key);

struct CsvTable {
  std::string source;                                         //!< file name used in messages
  std::vector<std::pair<std::string, std::string>> metadata;  //!< "# key=value" comments, in order
  std::vector<std::string> comments;  //!< text after the '#' of each comment line, in order
  std::vector<std::string> columns;   //!< header names, trimmed
  std::size_t header_line = 0;        //!< 1-based line of the header
  std::size_t rows = 0;               //!< number of data rows
  std::vector<double> cells;          //!< row-major rows×columns; NaN where empty or "nan"
  std::vector<std::uint8_t> empty;    //!< row-major; 1 where the cell was empty
  std::vector<std::size_t> lines;     //!< 1-based file line of each data row
  //! Columns whose cells are text, not numbers (an attitude file's `mode`): not parsed, value NaN.
  //! Set by parse_csv's text_columns; text_flag has one entry per column once the header is read.
  std::vector<std::string> text_columns;
  std::vector<std::uint8_t> text_flag;

  std::size_t column_count() const { return columns.size(); }
  //! Index of a column by exact name, or nullopt.
  std::optional<std::size_t> find_column(std::string_view name) const;
  double cell(std::size_t row, std::size_t col) const { return cells[row * columns.size() + col]; }
  bool is_empty(std::size_t row, std::size_t col) const { return empty[row * columns.size() + col] != 0; }
  //! Last value of a metadata key, or nullopt.
  std::optional<std::string> meta(std::string_view key) const;
  //! "FILE:LINE: column 'NAME': " prefix for messages about a cell.
  std::string where(std::size_t row, std::size_t col) const;
};

//! [columns] widest header read (a gyro log has at most 64 gyros and a few more columns).
inline constexpr std::size_t kMaxColumns = 1024;

//! `s` without its leading blanks and tabs and its trailing blanks, tabs and CR: a cell as the reader sees
//! it.
std::string_view trim_blanks(std::string_view s);
//! Strict number parse of a whole cell: plain decimal ("-1.5", "2e-3", a leading '+'), "nan" or
//! "inf" (any case). Hexadecimal, a decimal comma, blanks or trailing text are refused.
bool parse_number(std::string_view text, double& out);
//! A finite plain decimal number (as parse_number, without nan and inf), or nullopt.
std::optional<double> parse_decimal(std::string_view text);
//! Adds the "key=value" tokens of a comment's text (after the '#') to `metadata`. Tokens are separated
//! by blanks or commas; a comma followed at once by text without '=' is part of the value (a decimal
//! comma "-23,2" stays in the value, for its reader to refuse). %XX escapes of keys and values are undone.
void parse_metadata_comment(std::string_view comment, Metadata& metadata);

//! Parses a whole table from text; `source` names it in messages.
Result<CsvTable> parse_csv(std::string_view text, std::string source);
//! The same with the named columns kept as text (not parsed; their cells NaN, never "empty").
Result<CsvTable> parse_csv(std::string_view text, std::string source, std::vector<std::string> text_columns);
//! Reads and parses a file (a regular file or a FIFO of at most kMaxTableBytes). A TDMS file (".tdms")
//! is read as the table its channels make (tetra/core/tdms.hpp, read_tdms_table).
Result<CsvTable> read_csv(const std::string& path);

//! Reads a table as it goes, with memory bounded by one block of text (about 1 MB) whatever the file's
//! length: the header and the comments before it on open(), then the rows block by block. Messages
//! and line numbers are those of read_csv. Comment lines between rows add their metadata to the
//! block they appear in (blocks start from the metadata before the header). A TDMS file (".tdms") is
//! read whole on open (read_tdms_table) and served in blocks of rows; `lines` are then 1-based rows.
class CsvStreamReader {
 public:
  CsvStreamReader() = default;
  CsvStreamReader(const CsvStreamReader&) = delete;
  CsvStreamReader& operator=(const CsvStreamReader&) = delete;
  ~CsvStreamReader();

  //! Opens `path` and reads up to the header line.
  Status open(const std::string& path);
  //! Source, metadata before the header, columns and header line; no rows.
  const CsvTable& header() const { return header_; }
  //! Replaces `block` by the header's columns and the next rows (at least one). False at the end.
  Result<bool> next(CsvTable& block);
  //! Bytes consumed so far and the file's size (0 when unknown, e.g. a pipe): for progress.
  std::uint64_t bytes_read() const { return consumed_; }
  std::uint64_t bytes_total() const { return total_; }

 private:
  Status refill();
  Status open_tdms(const std::string& path);
  bool next_tdms_rows(CsvTable& block);
  std::FILE* file_ = nullptr;
  std::string text_;     // unparsed text; whole lines are parsed from pos_
  std::size_t pos_ = 0;  // first unparsed byte of text_
  std::size_t line_no_ = 0;
  bool eof_ = false;
  std::uint64_t consumed_ = 0;
  std::uint64_t total_ = 0;
  CsvTable header_;
  std::unique_ptr<CsvTable> whole_;  // a TDMS file's table
  std::size_t whole_next_ = 0;       // its next row
};

//! Reads a whole file into a string (error names the file; at most kMaxTableBytes, see read_input).
Result<std::string> read_text_file(const std::string& path);
//! Writes one output of a run of its own (RunFiles: refuses a folder, replaces a regular file
//! atomically, writes a device or FIFO straight). Commands with several outputs use RunFiles.
Status write_text_file(const std::string& path, std::string_view content);

//! Appends the metadata line "# key=value": blanks, commas, '%' and control characters of the key and
//! the value, and '=' of the key, are written %XX (read back by parse_csv), so any key and value
//! round-trip: a key "x units=dps" stays that key, never becomes "units".
void append_metadata(std::string& out, std::string_view key, std::string_view value);
//! Appends the shortest decimal text that reads back to exactly `value` ("nan" for NaN).
void append_double(std::string& out, double value);
//! The most characters format_double writes ("-2.2250738585072014e-308").
inline constexpr std::size_t kMaxDoubleChars = 24;
//! append_double's text written at `first` (room for kMaxDoubleChars); returns its end. For a writer
//! that formats many numbers into a buffer of its own.
char* format_double(char* first, double value);
//! Appends `value` in fixed notation with `decimals` digits after the point.
void append_fixed(std::string& out, double value, int decimals);
//! Appends an integer.
void append_int(std::string& out, long long value);

}  // namespace tetra
