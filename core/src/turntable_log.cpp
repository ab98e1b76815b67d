#include "tetra/core/turntable_log.hpp"

#include <cmath>

#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "turntable_log_internal.hpp"

namespace tetra {

std::optional<std::string> TurntableLog::meta(const std::string& key) const {
  return last_meta(metadata, key);
}

namespace turntable_detail {

namespace {
constexpr const char* kFixedNames[4] = {"sequence", "time_s", "inner_deg", "outer_deg"};
}  // namespace

Result<Columns> find_columns(const CsvTable& t) {
  Columns c;
  const std::string head = t.source + ":" + std::to_string(t.header_line) + ": header: ";
  for (int k = 0; k < 4; ++k) {
    const auto col = t.find_column(kFixedNames[k]);
    if (!col) return bad_input(head + "missing column '" + kFixedNames[k] + "'");
    c.fixed[k] = *col;
  }
  for (int id = 1;; ++id) {
    const auto col = t.find_column("g" + std::to_string(id));
    if (!col) break;
    c.gyro.push_back(*col);
  }
  if (c.gyro.size() < 3) {
    return bad_input(head + std::to_string(c.gyro.size()) +
                     " gyro columns (g1, g2, ...) found, calibration needs at least 3");
  }
  if (4 + c.gyro.size() != t.column_count()) {
    for (const auto& name : t.columns) {
      bool known = false;
      for (const char* n : kFixedNames) known = known || name == n;
      for (std::size_t g = 0; g < c.gyro.size(); ++g) known = known || name == "g" + std::to_string(g + 1);
      if (!known) return bad_input(head + "unknown column '" + name + "'");
    }
  }
  return c;
}

Status check_row(const CsvTable& t, const Columns& c, std::size_t r, const double* previous_time_s) {
  for (std::size_t k = 0; k < 4; ++k) {
    if (t.is_empty(r, c.fixed[k]) || !std::isfinite(t.cell(r, c.fixed[k]))) {
      return bad_input(t.where(r, c.fixed[k]) + "a finite number is required");
    }
  }
  const double seq = t.cell(r, c.fixed[0]);
  if (seq != std::floor(seq) || seq < 1 || seq > 1e6) {
    return bad_input(t.where(r, c.fixed[0]) + "sequence must be a positive integer");
  }
  const double time_s = t.cell(r, c.fixed[1]);
  if (previous_time_s != nullptr && time_s <= *previous_time_s) {
    return bad_input(t.where(r, c.fixed[1]) + "time goes backwards or repeats (" + std::to_string(time_s) +
                     " after " + std::to_string(*previous_time_s) + ")");
  }
  for (const std::size_t col : c.gyro) {
    if (t.is_empty(r, col) || !std::isfinite(t.cell(r, col))) {
      return bad_input(t.where(r, col) + "a finite voltage is required");
    }
  }
  return ok_status();
}

void append_block_metadata(const CsvTable& block, std::size_t header_entries, Metadata& metadata) {
  if (block.metadata.size() <= header_entries) return;
  metadata.insert(metadata.end(), block.metadata.begin() + static_cast<std::ptrdiff_t>(header_entries),
                  block.metadata.end());
}

}  // namespace turntable_detail

namespace {

using turntable_detail::Columns;
using turntable_detail::find_columns;

// Checks the rows of `t` and appends them to `log` (times must increase across calls too).
Status append_rows(const CsvTable& t, const Columns& c, TurntableLog& log) {
  for (std::size_t r = 0; r < t.rows; ++r) {
    const double* previous_time_s = log.time_s.empty() ? nullptr : &log.time_s.back();
    if (Status s = turntable_detail::check_row(t, c, r, previous_time_s); !s) return s;
    log.sequence.push_back(static_cast<int>(t.cell(r, c.fixed[0])));
    log.time_s.push_back(t.cell(r, c.fixed[1]));
    log.inner_deg.push_back(t.cell(r, c.fixed[2]));
    log.outer_deg.push_back(t.cell(r, c.fixed[3]));
    for (const std::size_t col : c.gyro) log.g_V.push_back(t.cell(r, col));
  }
  log.lines.insert(log.lines.end(), t.lines.begin(), t.lines.end());
  return ok_status();
}

// The log's fields known from its header.
TurntableLog empty_log(const CsvTable& header, const Columns& c) {
  TurntableLog log;
  log.source = header.source;
  log.metadata = header.metadata;
  log.gyro_count = static_cast<int>(c.gyro.size());
  return log;
}

Result<TurntableLog> turntable_from_table(CsvTable&& t) {
  auto c = find_columns(t);
  if (!c) return c.error();
  if (t.rows == 0) return bad_input(t.source + ": no data rows");
  TurntableLog log = empty_log(t, *c);
  if (Status s = append_rows(t, *c, log); !s) return s.error();
  return log;
}

// Room for the rows the file's size suggests after its first block (5 % spare), so the columns do not
// grow by doubling (a copy, and up to twice the memory, at each step).
void reserve_rows(const CsvStreamReader& reader, std::size_t first_rows, TurntableLog& log) {
  if (reader.bytes_total() == 0 || reader.bytes_read() == 0 || first_rows == 0) return;
  const double per_row = static_cast<double>(reader.bytes_read()) / static_cast<double>(first_rows);
  const auto rows = static_cast<std::size_t>(1.05 * static_cast<double>(reader.bytes_total()) / per_row) + 1;
  const auto ng = static_cast<std::size_t>(log.gyro_count);
  log.sequence.reserve(rows);
  log.time_s.reserve(rows);
  log.inner_deg.reserve(rows);
  log.outer_deg.reserve(rows);
  log.g_V.reserve(rows * ng);
  log.lines.reserve(rows);
}

}  // namespace

Result<TurntableLog> parse_turntable_log(std::string_view text, std::string source) {
  auto table = parse_csv(text, std::move(source));
  if (!table) return table.error();
  return turntable_from_table(std::move(table.value()));
}

// Block by block: the file's text and its table of cells are never whole in memory, only the log's
// columns (about 68 bytes a row with 4 gyros, against about 235 for the whole-file read). Same checks,
// messages and lines as parse_turntable_log; the same size bound as a whole-file read.
Result<TurntableLog> read_turntable_log(const std::string& path) {
  if (Status s = check_input(path, kMaxTableBytes, false); !s) return s.error();
  CsvStreamReader reader;
  if (Status s = reader.open(path); !s) return s.error();
  auto c = find_columns(reader.header());
  if (!c) return c.error();
  TurntableLog log = empty_log(reader.header(), *c);
  const std::size_t header_entries = reader.header().metadata.size();
  CsvTable block;
  while (true) {
    auto more = reader.next(block);
    if (!more) return more.error();
    turntable_detail::append_block_metadata(block, header_entries,
                                            log.metadata);  // at the end: comment lines after the last row
    if (!*more) break;
    if (reader.bytes_read() > kMaxTableBytes) {  // a FIFO (a regular file was checked at opening)
      return bad_input(path + ": is larger than the limit of " + std::to_string(kMaxTableBytes >> 30) +
                       " GiB for this kind of file");
    }
    if (log.rows() == 0) reserve_rows(reader, block.rows, log);
    if (Status s = append_rows(block, *c, log); !s) return s.error();
  }
  if (log.rows() == 0) return bad_input(log.source + ": no data rows");
  return log;
}

std::string format_turntable_log(const TurntableLog& log) {
  std::string out;
  out.reserve(log.rows() * static_cast<std::size_t>(40 + 14 * log.gyro_count));
  for (const auto& [k, v] : log.metadata) append_metadata(out, k, v);
  out += "sequence,time_s,inner_deg,outer_deg";
  for (int g = 1; g <= log.gyro_count; ++g) out += ",g" + std::to_string(g);
  out += '\n';
  for (std::size_t r = 0; r < log.rows(); ++r) {
    append_int(out, log.sequence[r]);
    out += ',';
    append_double(out, log.time_s[r]);
    out += ',';
    append_double(out, log.inner_deg[r]);
    out += ',';
    append_double(out, log.outer_deg[r]);
    for (int g = 0; g < log.gyro_count; ++g) {
      out += ',';
      append_double(out, log.g(r, g));
    }
    out += '\n';
  }
  return out;
}

Status write_turntable_log(const std::string& path, const TurntableLog& log) {
  return write_text_file(path, format_turntable_log(log));
}

}  // namespace tetra
