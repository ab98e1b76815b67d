#include "tetra/core/gyro_log.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

#include "tetra/core/csv.hpp"

namespace tetra {

std::optional<std::string> GyroLog::meta(const std::string& key) const {
  return last_meta(metadata, key);
}

namespace {

Result<GyroLog> from_table(CsvTable&& t) {
  GyroLog log;
  log.source = t.source;
  log.metadata = std::move(t.metadata);
  const std::string head = t.source + ":" + std::to_string(t.header_line) + ": header: ";

  const auto time_col = t.find_column("time_s");
  if (!time_col) return bad_input(head + "missing column 'time_s'");

  // Gyro columns g1..gN, contiguous from 1.
  std::vector<std::size_t> gyro_cols;
  for (int id = 1;; ++id) {
    const auto c = t.find_column("g" + std::to_string(id));
    if (!c) break;
    gyro_cols.push_back(*c);
  }
  if (gyro_cols.empty()) return bad_input(head + "no gyro columns (expected g1, g2, ...)");
  log.gyro_count = static_cast<int>(gyro_cols.size());

  static constexpr std::array<const char*, 4> kRefNames = {"ref_qw", "ref_qx", "ref_qy", "ref_qz"};
  std::array<std::size_t, 4> ref_cols{};
  int ref_found = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    if (const auto c = t.find_column(kRefNames[k])) {
      ref_cols[k] = *c;
      ++ref_found;
    }
  }
  if (ref_found != 0 && ref_found != 4)
    return bad_input(head + "reference columns must be all of ref_qw,ref_qx,ref_qy,ref_qz");
  log.has_reference = ref_found == 4;

  // Every column must be used: a typo must not pass silently (duplicates are refused by parse_csv).
  std::vector<bool> used(t.column_count(), false);
  used[*time_col] = true;
  for (const std::size_t c : gyro_cols) used[c] = true;
  if (log.has_reference) {
    for (const std::size_t c : ref_cols) used[c] = true;
  }
  for (std::size_t c = 0; c < t.column_count(); ++c) {
    if (!used[c]) {
      return bad_input(head + "unknown column '" + t.columns[c] + "' (expected time_s, g1..g" +
                       std::to_string(log.gyro_count) + ", optional ref_qw..ref_qz)");
    }
  }

  if (const auto units = log.meta("units")) {
    if (*units == "dps") {
      log.units_dps = true;
    } else if (*units != "V") {
      return bad_input(t.source + ": metadata units='" + *units + "': expected 'V' or 'dps'");
    }
  }

  const std::size_t n = t.rows;
  const auto ng = static_cast<std::size_t>(log.gyro_count);
  log.time_s.resize(n);
  log.values.resize(n * ng);
  log.present.resize(n * ng);
  if (log.has_reference) {
    log.reference_wxyz.resize(n);
    log.reference_present.resize(n);
  }
  for (std::size_t r = 0; r < n; ++r) {
    if (t.is_empty(r, *time_col) || !std::isfinite(t.cell(r, *time_col))) {
      return bad_input(t.where(r, *time_col) + "time must be a finite number");
    }
    log.time_s[r] = t.cell(r, *time_col);
    for (std::size_t g = 0; g < ng; ++g) {
      log.values[r * ng + g] = t.cell(r, gyro_cols[g]);
      log.present[r * ng + g] = t.is_empty(r, gyro_cols[g]) ? 0 : 1;
    }
    if (log.has_reference) {
      int filled = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        filled += t.is_empty(r, ref_cols[k]) ? 0 : 1;
        log.reference_wxyz[r][k] = t.cell(r, ref_cols[k]);
      }
      if (filled != 0 && filled != 4) {
        return bad_input(t.where(r, ref_cols[0]) + "reference quaternion is partly empty");
      }
      if (filled == 4) {
        const auto& q = log.reference_wxyz[r];
        const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
          return bad_input(t.where(r, ref_cols[0]) + "reference quaternion is not of unit norm");
        }
      }
      log.reference_present[r] = filled == 4 ? 1 : 0;
    }
  }
  log.lines = std::move(t.lines);
  return log;
}

}  // namespace

Result<GyroLog> parse_gyro_log(std::string_view text, std::string source) {
  auto table = parse_csv(text, std::move(source));
  if (!table) return table.error();
  return from_table(std::move(table.value()));
}

Result<GyroLog> read_gyro_log(const std::string& path) {
  auto table = read_csv(path);
  if (!table) return table.error();
  return from_table(std::move(table.value()));
}

GyroLogWriter::~GyroLogWriter() = default;

Status GyroLogWriter::open(const std::string& path, int gyro_count, bool with_reference, bool units_dps,
                           const std::vector<std::pair<std::string, std::string>>& comments) {
  if (out_ != nullptr) return failure(out_->path() + ": writer already open");
  own_ = std::make_unique<RunFiles>();
  auto out = own_->add(path, "output");
  if (!out) return out.error();
  return open(**out, gyro_count, with_reference, units_dps, comments);
}

Status GyroLogWriter::open(OutputFile& out, int gyro_count, bool with_reference, bool units_dps,
                           const std::vector<std::pair<std::string, std::string>>& comments) {
  if (out_ != nullptr) return failure(out_->path() + ": writer already open");
  if (gyro_count < 1) return bad_input(out.path() + ": a gyro log needs at least one gyro column");
  out_ = &out;
  gyro_count_ = gyro_count;
  with_reference_ = with_reference;
  buffer_.clear();
  if (units_dps) buffer_ += "# units=dps\n";
  for (const auto& [k, v] : comments) append_metadata(buffer_, k, v);
  buffer_ += "time_s";
  for (int i = 1; i <= gyro_count; ++i) buffer_ += ",g" + std::to_string(i);
  if (with_reference) buffer_ += ",ref_qw,ref_qx,ref_qy,ref_qz";
  buffer_ += '\n';
  return ok_status();
}

Status GyroLogWriter::write(double time_s, std::span<const double> values,
                            std::span<const std::uint8_t> present,
                            const std::optional<std::array<double, 4>>& reference_wxyz) {
  if (out_ == nullptr) return failure("gyro log writer is not open");
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
  const Status flushed = flush();
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
