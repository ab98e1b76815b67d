#include "tetra/core/turntable_log.hpp"

#include <cmath>

#include "tetra/core/csv.hpp"

namespace tetra {

std::optional<std::string> TurntableLog::meta(const std::string& key) const {
  return last_meta(metadata, key);
}

namespace {

Result<TurntableLog> from_table(CsvTable&& t) {
  TurntableLog log;
  log.source = t.source;
  log.metadata = t.metadata;
  const std::string head = t.source + ":" + std::to_string(t.header_line) + ": header: ";
  std::size_t cols[4] = {};
  const char* names[4] = {"sequence", "time_s", "inner_deg", "outer_deg"};
  for (int k = 0; k < 4; ++k) {
    const auto c = t.find_column(names[k]);
    if (!c) return bad_input(head + "missing column '" + names[k] + "'");
    cols[k] = *c;
  }
  std::vector<std::size_t> gyro_cols;
  for (int id = 1;; ++id) {
    const auto c = t.find_column("g" + std::to_string(id));
    if (!c) break;
    gyro_cols.push_back(*c);
  }
  if (gyro_cols.size() < 3) {
    return bad_input(head + std::to_string(gyro_cols.size()) +
                     " gyro columns (g1, g2, ...) found, calibration needs at least 3");
  }
  if (4 + gyro_cols.size() != t.column_count()) {
    for (const auto& name : t.columns) {
      bool known = false;
      for (const char* n : names) known = known || name == n;
      for (std::size_t g = 0; g < gyro_cols.size(); ++g) known = known || name == "g" + std::to_string(g + 1);
      if (!known) return bad_input(head + "unknown column '" + name + "'");
    }
  }
  if (t.rows == 0) return bad_input(t.source + ": no data rows");

  log.gyro_count = static_cast<int>(gyro_cols.size());
  const std::size_t n = t.rows;
  const auto ng = gyro_cols.size();
  log.sequence.resize(n);
  log.time_s.resize(n);
  log.inner_deg.resize(n);
  log.outer_deg.resize(n);
  log.g_V.resize(n * ng);
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t k = 0; k < 4; ++k) {
      if (t.is_empty(r, cols[k]) || !std::isfinite(t.cell(r, cols[k]))) {
        return bad_input(t.where(r, cols[k]) + "a finite number is required");
      }
    }
    const double seq = t.cell(r, cols[0]);
    if (seq != std::floor(seq) || seq < 1 || seq > 1e6) {
      return bad_input(t.where(r, cols[0]) + "sequence must be a positive integer");
    }
    log.sequence[r] = static_cast<int>(seq);
    log.time_s[r] = t.cell(r, cols[1]);
    if (r > 0 && log.time_s[r] <= log.time_s[r - 1]) {
      return bad_input(t.where(r, cols[1]) + "time goes backwards or repeats (" +
                       std::to_string(log.time_s[r]) + " after " + std::to_string(log.time_s[r - 1]) + ")");
    }
    log.inner_deg[r] = t.cell(r, cols[2]);
    log.outer_deg[r] = t.cell(r, cols[3]);
    for (std::size_t g = 0; g < ng; ++g) {
      const double v = t.cell(r, gyro_cols[g]);
      if (t.is_empty(r, gyro_cols[g]) || !std::isfinite(v)) {
        return bad_input(t.where(r, gyro_cols[g]) + "a finite voltage is required");
      }
      log.g_V[r * ng + g] = v;
    }
  }
  log.lines = std::move(t.lines);
  return log;
}

}  // namespace

Result<TurntableLog> parse_turntable_log(std::string_view text, std::string source) {
  auto table = parse_csv(text, std::move(source));
  if (!table) return table.error();
  return from_table(std::move(table.value()));
}

Result<TurntableLog> read_turntable_log(const std::string& path) {
  auto table = read_csv(path);
  if (!table) return table.error();
  return from_table(std::move(table.value()));
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
