#include "tetra/core/sample_parser.hpp"

#include <cmath>

#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"

namespace tetra {

namespace {

// The comma-separated fields of a line, at most `limit` (one more means "too many").
void split_protocol_fields(std::string_view line, std::size_t limit, std::vector<std::string_view>& fields) {
  fields.clear();
  while (fields.size() <= limit) {
    const std::size_t comma = line.find(',');
    fields.push_back(trim_blanks(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

}  // namespace

void LineProtocolParser::parse_line(std::string_view line, std::vector<RawGyroSample>& out) {
  ++line_no_;
  line = trim_blanks(line);
  if (line.empty() || line.front() == '#') return;
  const std::string where = "line " + std::to_string(line_no_) + ": ";
  thread_local std::vector<std::string_view> f;
  const auto n = static_cast<std::size_t>(gyro_count_);
  split_protocol_fields(line, n + 2, f);
  double time_s = 0.0;
  if (f.size() < 3) return refuse(where + "expected TIME_S,GYRO,RAW or TIME_S,all,RAW1..RAWN");
  if (!parse_number(f[0], time_s) || log_time_problem(time_s))
    return refuse(where + "time_s is not a finite time");
  const std::size_t first = out.size();
  if (f[1] == "all") {
    if (f.size() != n + 2) {
      return refuse(where + "'all' needs " + std::to_string(n) + " raw values, got " +
                    std::to_string(f.size() - 2) + (f.size() > n + 2 ? " or more" : ""));
    }
    for (std::size_t g = 0; g < n; ++g) {
      double raw = 0.0;
      if (!parse_number(f[g + 2], raw) || std::isinf(raw)) {
        out.resize(first);
        return refuse(where + "raw value " + std::to_string(g + 1) + " is not a number");
      }
      out.push_back({time_s, static_cast<int>(g + 1), raw});
    }
    return accept();
  }
  if (f.size() != 3) return refuse(where + "one gyro takes one raw value (TIME_S,GYRO,RAW)");
  double id = 0.0;
  if (!parse_number(f[1], id) || id != std::floor(id) || id < 1 || id > gyro_count_) {
    return refuse(where + "gyro must be 1.." + std::to_string(gyro_count_) + " or 'all'");
  }
  double raw = 0.0;
  if (!parse_number(f[2], raw) || std::isinf(raw)) return refuse(where + "raw value is not a number");
  out.push_back({time_s, static_cast<int>(id), raw});
  accept();
}

void LineProtocolParser::feed(std::span<const std::uint8_t> bytes, std::vector<RawGyroSample>& out) {
  for (const std::uint8_t b : bytes) {
    if (b == '\n') {
      if (overlong_) {
        ++line_no_;
        refuse("line " + std::to_string(line_no_) + ": longer than " + std::to_string(kMaxLineBytes) +
               " bytes");
        overlong_ = false;
      } else {
        parse_line(pending_, out);
      }
      pending_.clear();
      continue;
    }
    if (overlong_) continue;
    if (pending_.size() >= kMaxLineBytes) {
      overlong_ = true;
      pending_.clear();
      continue;
    }
    pending_ += static_cast<char>(b);
  }
}

void LineProtocolParser::flush(std::vector<RawGyroSample>& out) {
  const std::uint8_t newline = '\n';
  if (!pending_.empty() || overlong_) feed(std::span(&newline, 1), out);
}

}  // namespace tetra
