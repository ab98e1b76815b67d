#include "tetra/core/gyro_log.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "gyro_log_h5.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/tdms.hpp"

namespace tetra {

std::optional<std::string> log_time_problem(double time_s) {
  if (!std::isfinite(time_s)) return std::string("time must be a finite number");
  if (std::abs(time_s) <= kMaxLogTime_s) return std::nullopt;
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", time_s);
  return std::string("time ") + text +
         " s is beyond ±9e9 s (times become 64-bit nanoseconds): give times relative to an epoch, e.g. the "
         "first";
}

std::optional<std::string> GyroLog::meta(const std::string& key) const {
  return last_meta(metadata, key);
}

namespace {

// The columns of a gyro log's table: time, g1..gN contiguous from 1, optionally the four reference columns.
struct LogColumns {
  std::size_t time = 0;
  std::vector<std::size_t> gyros;
  std::array<std::size_t, 4> reference{};
  bool has_reference = false;
  std::optional<std::size_t> reference_stamp;  //!< ref_stamp_s
};

Result<LogColumns> find_log_columns(const CsvTable& t, const std::string& head) {
  LogColumns cols;
  const auto time_col = t.find_column("time_s");
  if (!time_col) return bad_input(head + "missing column 'time_s'");
  cols.time = *time_col;
  for (int id = 1;; ++id) {
    const auto c = t.find_column("g" + std::to_string(id));
    if (!c) break;
    cols.gyros.push_back(*c);
  }
  if (cols.gyros.empty()) return bad_input(head + "no gyro columns (expected g1, g2, ...)");
  static constexpr std::array<const char*, 4> kRefNames = {"ref_qw", "ref_qx", "ref_qy", "ref_qz"};
  int ref_found = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    if (const auto c = t.find_column(kRefNames[k])) {
      cols.reference[k] = *c;
      ++ref_found;
    }
  }
  if (ref_found != 0 && ref_found != 4)
    return bad_input(head + "reference columns must be all of ref_qw,ref_qx,ref_qy,ref_qz");
  cols.has_reference = ref_found == 4;
  cols.reference_stamp = t.find_column("ref_stamp_s");
  if (cols.reference_stamp && !cols.has_reference)
    return bad_input(head + "ref_stamp_s needs the reference columns ref_qw,ref_qx,ref_qy,ref_qz");
  return cols;
}

// Every column must be used: a typo must not pass silently (duplicates are refused by parse_csv).
Status check_every_column_used(const CsvTable& t, const LogColumns& cols, const std::string& head) {
  std::vector<bool> used(t.column_count(), false);
  used[cols.time] = true;
  for (const std::size_t c : cols.gyros) used[c] = true;
  if (cols.has_reference) {
    for (const std::size_t c : cols.reference) used[c] = true;
  }
  if (cols.reference_stamp) used[*cols.reference_stamp] = true;
  for (std::size_t c = 0; c < t.column_count(); ++c) {
    if (!used[c]) {
      return bad_input(head + "unknown column '" + t.columns[c] + "' (expected time_s, g1..g" +
                       std::to_string(cols.gyros.size()) + ", optional ref_qw..ref_qz, ref_stamp_s)");
    }
  }
  return ok_status();
}

Status read_units(GyroLog& log, const std::string& source) {
  if (const auto units = log.meta("units")) {
    if (*units == "dps") {
      log.units_dps = true;
    } else if (*units != "V") {
      return bad_input(source + ": metadata units='" + *units + "': expected 'V' or 'dps'");
    }
  }
  return ok_status();
}

// Row r's reference quaternion: all four cells or none, of unit norm.
Status read_reference_row(const CsvTable& t, const LogColumns& cols, std::size_t r, GyroLog& log) {
  int filled = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    filled += t.is_empty(r, cols.reference[k]) ? 0 : 1;
    log.reference_wxyz[r][k] = t.cell(r, cols.reference[k]);
  }
  if (filled != 0 && filled != 4) {
    return bad_input(t.where(r, cols.reference[0]) + "reference quaternion is partly empty");
  }
  if (filled == 4) {
    const auto& q = log.reference_wxyz[r];
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
      return bad_input(t.where(r, cols.reference[0]) + "reference quaternion is not of unit norm");
    }
  }
  log.reference_present[r] = filled == 4 ? 1 : 0;
  return ok_status();
}

// Row r's ref_stamp_s: empty (the row's time), or a time no later than the row's, on a row with a reference.
Status read_reference_stamp(const CsvTable& t, std::size_t column, std::size_t r, GyroLog& log) {
  log.reference_stamp_s[r] = std::numeric_limits<double>::quiet_NaN();
  if (t.is_empty(r, column)) return ok_status();
  const double stamp = t.cell(r, column);
  if (auto why = log_time_problem(stamp)) return bad_input(t.where(r, column) + *why);
  if (log.reference_present[r] == 0)
    return bad_input(t.where(r, column) + "ref_stamp_s on a row without reference");
  if (stamp > log.time_s[r])
    return bad_input(t.where(r, column) + "ref_stamp_s is later than the row's time_s");
  log.reference_stamp_s[r] = stamp;
  return ok_status();
}

Status read_rows(const CsvTable& t, const LogColumns& cols, GyroLog& log) {
  const std::size_t n = t.rows;
  const auto ng = static_cast<std::size_t>(log.gyro_count);
  log.time_s.resize(n);
  log.values.resize(n * ng);
  log.present.resize(n * ng);
  if (log.has_reference) {
    log.reference_wxyz.resize(n);
    log.reference_present.resize(n);
  }
  if (log.has_reference_stamp) log.reference_stamp_s.resize(n);
  for (std::size_t r = 0; r < n; ++r) {
    if (t.is_empty(r, cols.time)) return bad_input(t.where(r, cols.time) + "time must be a finite number");
    if (auto why = log_time_problem(t.cell(r, cols.time))) return bad_input(t.where(r, cols.time) + *why);
    log.time_s[r] = t.cell(r, cols.time);
    for (std::size_t g = 0; g < ng; ++g) {
      log.values[r * ng + g] = t.cell(r, cols.gyros[g]);
      log.present[r * ng + g] = t.is_empty(r, cols.gyros[g]) ? 0 : 1;
    }
    if (log.has_reference) {
      if (Status s = read_reference_row(t, cols, r, log); !s) return s;
    }
    if (cols.reference_stamp) {
      if (Status s = read_reference_stamp(t, *cols.reference_stamp, r, log); !s) return s;
    }
  }
  return ok_status();
}

// The table's columns, units and rows into `log` (all but its metadata, comments and lines). `log`'s
// vectors keep their storage: a block refilled from a table of the same size allocates nothing.
Status fill_from_table(const CsvTable& t, GyroLog& log) {
  log.source = t.source;
  const std::string head = t.source + ":" + std::to_string(t.header_line) + ": header: ";
  auto cols = find_log_columns(t, head);
  if (!cols) return cols.error();
  log.gyro_count = static_cast<int>(cols->gyros.size());
  log.has_reference = cols->has_reference;
  log.has_reference_stamp = cols->reference_stamp.has_value();
  log.units_dps = false;
  if (Status s = check_every_column_used(t, *cols, head); !s) return s;
  if (Status s = read_units(log, t.source); !s) return s;
  return read_rows(t, *cols, log);
}

Result<GyroLog> from_table(CsvTable&& t) {
  GyroLog log;
  log.metadata = std::move(t.metadata);
  log.comments = std::move(t.comments);
  if (Status s = fill_from_table(t, log); !s) return s.error();
  log.lines = std::move(t.lines);
  return log;
}

// CSV logs block by block: each block of rows goes through from_table, so every check and message is
// the whole-file reader's. Units must not change after the header (a block cannot see later comments).
class CsvGyroLogReader final : public GyroLogReader {
 public:
  Status open(const std::string& path) {
    if (Status s = csv_.open(path); !s) return s;
    CsvTable head = csv_.header();
    auto log = from_table(std::move(head));
    if (!log) return log.error();
    header_ = std::move(log.value());
    return ok_status();
  }
  // The table and the block are refilled in place (no allocation per block once they have grown).
  Result<bool> next(GyroLog& block) override {
    auto more = csv_.next(table_);
    if (!more || !*more) return more;
    block.metadata = table_.metadata;
    block.comments = table_.comments;
    if (Status s = fill_from_table(table_, block); !s) return s.error();
    block.lines = table_.lines;
    if (block.units_dps != header_.units_dps) {
      return bad_input(header_.source + ":" + std::to_string(block.lines.front()) +
                       ": metadata 'units' changes after the header: put it before the header line");
    }
    return true;
  }
  double fraction_read() const override {
    return csv_.bytes_total() == 0
               ? 0.0
               : static_cast<double>(csv_.bytes_read()) / static_cast<double>(csv_.bytes_total());
  }

 private:
  CsvStreamReader csv_;
  CsvTable table_;
};

}  // namespace

bool is_hdf5_path(const std::string& path) {
  auto ends_with = [&](std::string_view ext) {
    return path.size() >= ext.size() && path.compare(path.size() - ext.size(), ext.size(), ext) == 0;
  };
  return ends_with(".h5") || ends_with(".hdf5");
}

Result<std::unique_ptr<GyroLogReader>> GyroLogReader::open(const std::string& path) {
  if (is_hdf5_path(path)) return open_gyro_log_h5_reader(path);
  auto reader = std::make_unique<CsvGyroLogReader>();
  if (Status s = reader->open(path); !s) return s.error();
  return std::unique_ptr<GyroLogReader>(std::move(reader));
}

Result<GyroLog> parse_gyro_log(std::string_view text, std::string source) {
  auto table = parse_csv(text, std::move(source));
  if (!table) return table.error();
  return from_table(std::move(table.value()));
}

Result<GyroLog> read_gyro_log(const std::string& path) {
  if (is_hdf5_path(path)) return read_gyro_log_h5(path);
  auto table = read_csv(path);
  if (!table) return table.error();
  return from_table(std::move(table.value()));
}

GyroLogWriter::GyroLogWriter() = default;

GyroLogWriter::~GyroLogWriter() = default;

Status GyroLogWriter::open(const std::string& path, int gyro_count, bool with_reference, bool units_dps,
                           const std::vector<std::pair<std::string, std::string>>& comments) {
  auto out = open_own(path);
  if (!out) return out.error();
  return open(**out, gyro_count, with_reference, units_dps, comments);
}

Status GyroLogWriter::open(OutputFile& out, int gyro_count, bool with_reference, bool units_dps,
                           const std::vector<std::pair<std::string, std::string>>& comments) {
  // The comment lines as they are written: text after '#', values escaped by append_metadata.
  std::vector<std::string> lines;
  if (units_dps) lines.emplace_back(" units=dps");
  for (const auto& [k, v] : comments) {
    std::string line;
    append_metadata(line, k, v);
    lines.push_back(line.substr(1, line.size() - 2));  // without '#' and the newline
  }
  return open_output(out, gyro_count, with_reference, lines);
}

Status GyroLogWriter::open_like(const std::string& path, const GyroLog& header) {
  auto out = open_own(path);
  if (!out) return out.error();
  return open_like(**out, header);
}

Status GyroLogWriter::open_like(OutputFile& out, const GyroLog& header) {
  with_reference_stamp_ = header.has_reference_stamp;
  return open_output(out, header.gyro_count, header.has_reference, header.comments);
}

Result<OutputFile*> GyroLogWriter::open_own(const std::string& path) {
  if (out_ != nullptr) return failure(out_->path() + ": writer already open");
  own_ = std::make_unique<RunFiles>();
  return own_->add(path, "output");
}

Status GyroLogWriter::open_output(OutputFile& out, int gyro_count, bool with_reference,
                                  const std::vector<std::string>& comments) {
  if (out_ != nullptr) return failure(out_->path() + ": writer already open");
  if (gyro_count < 1) return bad_input(out.path() + ": a gyro log needs at least one gyro column");
  if (is_tdms_path(out.path())) {
    return bad_input(out.path() +
                     ": tetra reads TDMS logs but does not write them: name the output .csv or .h5");
  }
  for (std::size_t i = 0; i < comments.size(); ++i) {
    if (comments[i].find_first_of("\n\r") != std::string::npos) {  // it would end the comment line
      return bad_input(out.path() + ": comment " + std::to_string(i + 1) +
                       " holds a line break (a comment is one line)");
    }
  }
  if (with_reference_stamp_ && (!with_reference || is_hdf5_path(out.path()))) {
    return bad_input(out.path() + ": a ref_stamp_s column needs the reference columns, in a CSV log");
  }
  if (is_hdf5_path(out.path())) {
    auto file_path = out.library_path();
    if (!file_path) return file_path.error();
    h5_ = std::make_unique<GyroLogH5Writer>();
    if (Status s = h5_->open(*file_path, out.path(), gyro_count, with_reference, comments, compress_); !s) {
      h5_.reset();
      return s;
    }
    out_ = &out;
    return ok_status();
  }
  out_ = &out;
  gyro_count_ = gyro_count;
  with_reference_ = with_reference;
  buffer_.clear();
  for (const std::string& c : comments) buffer_ += "#" + c + "\n";
  buffer_ += "time_s";
  for (int i = 1; i <= gyro_count; ++i) buffer_ += ",g" + std::to_string(i);
  if (with_reference) buffer_ += ",ref_qw,ref_qx,ref_qy,ref_qz";
  if (with_reference_stamp_) buffer_ += ",ref_stamp_s";
  buffer_ += '\n';
  return ok_status();
}

Status GyroLogWriter::write(double time_s, std::span<const double> values,
                            std::span<const std::uint8_t> present,
                            const std::optional<std::array<double, 4>>& reference_wxyz,
                            std::optional<double> reference_stamp_s) {
  if (out_ == nullptr) return failure("gyro log writer is not open");
  if (h5_) return h5_->write(time_s, values, present, reference_wxyz);
  if (values.size() != static_cast<std::size_t>(gyro_count_) || present.size() != values.size()) {
    return failure(out_->path() + ": epoch has the wrong number of gyro values");
  }
  append_double(buffer_, time_s);
  for (std::size_t i = 0; i < values.size(); ++i) {
    buffer_ += ',';
    if (present[i] != 0) append_double(buffer_, values[i]);
  }
  if (with_reference_) {
    for (std::size_t k = 0; k < 4; ++k) {
      buffer_ += ',';
      if (reference_wxyz) append_double(buffer_, (*reference_wxyz)[k]);
    }
  }
  if (with_reference_stamp_) {
    buffer_ += ',';
    if (reference_wxyz && reference_stamp_s) append_double(buffer_, *reference_stamp_s);
  }
  buffer_ += '\n';
  if (buffer_.size() > (1U << 20)) return flush();
  return ok_status();
}

Status GyroLogWriter::flush() {
  if (Status st = out_->write(buffer_); !st) return st;
  buffer_.clear();
  return ok_status();
}

Status GyroLogWriter::close() {
  if (out_ == nullptr) return failure("gyro log writer is not open");
  Status flushed = ok_status();
  if (h5_) {
    flushed = h5_->close();
    h5_.reset();
  } else {
    flushed = flush();
  }
  out_ = nullptr;
  if (!flushed) return flushed;
  if (own_) {
    const Status committed = own_->commit();
    own_.reset();
    return committed;
  }
  return ok_status();
}

}  // namespace tetra
