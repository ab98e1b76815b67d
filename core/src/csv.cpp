#include "tetra/core/csv.hpp"

#include "tetra/core/input_files.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/tdms.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

namespace tetra {

std::string_view trim_blanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// Undoes append_metadata's %XX escapes; a '%' not followed by two hex digits stays as it is.
std::string unescape_meta(std::string_view value) {
  std::string out;
  out.reserve(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (value[i] == '%' && i + 2 < value.size() && hex_digit(value[i + 1]) >= 0 &&
        hex_digit(value[i + 2]) >= 0) {
      out += static_cast<char>(hex_digit(value[i + 1]) * 16 + hex_digit(value[i + 2]));
      i += 2;
    } else {
      out += value[i];
    }
  }
  return out;
}

}  // namespace

void parse_metadata_comment(std::string_view comment, Metadata& metadata) {
  // comment without the '#': tokens "key=value" separated by blanks or commas.
  std::size_t i = 0;
  while (i < comment.size()) {
    while (i < comment.size() && (comment[i] == ' ' || comment[i] == '\t' || comment[i] == ',')) ++i;
    std::size_t j = i;
    while (j < comment.size() && comment[j] != ' ' && comment[j] != '\t' && comment[j] != ',') ++j;
    std::string_view token = comment.substr(i, j - i);
    const std::size_t eq = token.find('=');
    // tetra writes ',' in a value as %2C: a bare comma followed at once by text that is no "key="
    // belongs to the value ("latitude_deg=-23,2", a decimal comma), so the value is read whole and
    // refused by its reader, never cut to "-23".
    while (eq != std::string_view::npos && j + 1 < comment.size() && comment[j] == ',' &&
           comment[j + 1] != ' ' && comment[j + 1] != '\t' && comment[j + 1] != ',') {
      std::size_t k = j + 1;
      while (k < comment.size() && comment[k] != ' ' && comment[k] != '\t' && comment[k] != ',') ++k;
      if (comment.substr(j + 1, k - j - 1).find('=') != std::string_view::npos) break;
      j = k;
      token = comment.substr(i, j - i);
    }
    if (eq != std::string_view::npos && eq > 0) {
      metadata.emplace_back(unescape_meta(token.substr(0, eq)), unescape_meta(token.substr(eq + 1)));
    }
    i = j;
  }
}

bool parse_number(std::string_view s, double& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty() || s.find('(') != std::string_view::npos) return false;  // no "nan(payload)"
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size();
}

std::optional<double> parse_decimal(std::string_view s) {
  double v = 0.0;
  if (!parse_number(s, v) || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<std::size_t> CsvTable::find_column(std::string_view name) const {
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == name) return i;
  }
  return std::nullopt;
}

std::optional<std::string> last_meta(const Metadata& metadata, std::string_view key) {
  std::optional<std::string> found;
  for (const auto& [k, v] : metadata) {
    if (k == key) found = v;
  }
  return found;
}

std::optional<std::string> CsvTable::meta(std::string_view key) const {
  return last_meta(metadata, key);
}

std::string CsvTable::where(std::size_t row, std::size_t col) const {
  return source + ":" + std::to_string(lines[row]) + ": column '" + columns[col] + "': ";
}

namespace {

// The comma-separated fields of `line`, each trimmed.
inline void split_fields(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      fields.push_back(trim_blanks(line.substr(start)));
      return;
    }
    fields.push_back(trim_blanks(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

// The header line: at most kMaxColumns named, distinct columns; marks the text columns.
Status parse_header(const std::vector<std::string_view>& fields, std::size_t line_no, CsvTable& t) {
  if (fields.size() > kMaxColumns) {
    return bad_input(t.source + ":" + std::to_string(line_no) + ": header: " + std::to_string(fields.size()) +
                     " columns, at most " + std::to_string(kMaxColumns) + " are read");
  }
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (fields[i].empty()) {
      return bad_input(t.source + ":" + std::to_string(line_no) + ": header: column " +
                       std::to_string(i + 1) + " has no name");
    }
    for (std::size_t k = 0; k < i; ++k) {
      if (fields[k] == fields[i]) {
        return bad_input(t.source + ":" + std::to_string(line_no) + ": header: column '" +
                         std::string(fields[i]) + "' appears twice");
      }
    }
    t.columns.emplace_back(fields[i]);
  }
  t.header_line = line_no;
  t.text_flag.assign(t.columns.size(), 0);
  for (std::size_t i = 0; i < t.columns.size(); ++i) {
    for (const std::string& name : t.text_columns) {
      if (name == t.columns[i]) t.text_flag[i] = 1;
    }
  }
  return ok_status();
}

// A data row: as many fields as the header; numbers, empty cells (NaN, flagged) or text columns' cells.
Status parse_row(const std::vector<std::string_view>& fields, std::size_t line_no, CsvTable& t) {
  if (fields.size() != t.columns.size()) {
    return bad_input(t.source + ":" + std::to_string(line_no) + ": expected " +
                     std::to_string(t.columns.size()) + " fields as in the header, found " +
                     std::to_string(fields.size()));
  }
  for (std::size_t c = 0; c < fields.size(); ++c) {
    const std::string_view cell = fields[c];
    if (c < t.text_flag.size() && t.text_flag[c] != 0) {
      t.cells.push_back(std::numeric_limits<double>::quiet_NaN());
      t.empty.push_back(0);
      continue;
    }
    if (cell.empty()) {
      t.cells.push_back(std::numeric_limits<double>::quiet_NaN());
      t.empty.push_back(1);
      continue;
    }
    double v = 0.0;
    if (!parse_number(cell, v)) {
      return bad_input(t.source + ":" + std::to_string(line_no) + ": column '" + t.columns[c] + "': '" +
                       std::string(cell.substr(0, 40)) + "' is not a number");
    }
    t.cells.push_back(v);
    t.empty.push_back(0);
  }
  t.lines.push_back(line_no);
  ++t.rows;
  return ok_status();
}

// Parses the lines of text[pos..] into `t`, numbering them after `line_no`; `pos` and `line_no`
// advance. The first non-comment line is the header (then stops if `header_only`); rows need it.
Status parse_lines(std::string_view text, std::size_t& pos, std::size_t& line_no, CsvTable& t,
                   bool& have_header, bool header_only) {
  std::vector<std::string_view> fields;
  while (pos < text.size()) {
    const char* begin = text.data() + pos;
    const void* nl = std::memchr(begin, '\n', text.size() - pos);
    const std::size_t len =
        nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - begin) : text.size() - pos;
    std::string_view line(begin, len);
    pos += len + 1;
    ++line_no;

    const std::string_view content = trim_blanks(line);
    if (content.empty()) continue;
    if (content.front() == '#') {
      parse_metadata_comment(content.substr(1), t.metadata);
      t.comments.emplace_back(content.substr(1));
      continue;
    }
    split_fields(line, fields);
    if (have_header) {
      if (Status s = parse_row(fields, line_no, t); !s) return s;
      continue;
    }
    if (Status s = parse_header(fields, line_no, t); !s) return s;
    have_header = true;
    if (header_only) return ok_status();
  }
  return ok_status();
}

// Bodies larger than this are parsed in two halves on two threads (a 2 h, 100 Hz log is ~45 MB).
constexpr std::size_t kParallelBytes = std::size_t{8} << 20;

void reserve_rows(CsvTable& t, std::string_view body) {
  // A row of C cells takes at least C bytes (C-1 commas and a newline): blank lines reserve nothing.
  const std::size_t lines = static_cast<std::size_t>(std::count(body.begin(), body.end(), '\n')) + 1;
  const std::size_t approx_rows =
      std::min(lines, body.size() / std::max<std::size_t>(t.columns.size(), 1) + 1);
  t.cells.reserve(approx_rows * t.columns.size());
  t.empty.reserve(approx_rows * t.columns.size());
  t.lines.reserve(approx_rows);
}

}  // namespace

Result<CsvTable> parse_csv(std::string_view text, std::string source) {
  return parse_csv(text, std::move(source), {});
}

Result<CsvTable> parse_csv(std::string_view text, std::string source, std::vector<std::string> text_columns) {
  CsvTable t;
  t.source = std::move(source);
  t.text_columns = std::move(text_columns);
  if (text.size() >= 3 && std::memcmp(text.data(), "\xEF\xBB\xBF", 3) == 0) text.remove_prefix(3);

  std::size_t pos = 0;
  std::size_t line_no = 0;
  bool have_header = false;
  if (Status s = parse_lines(text, pos, line_no, t, have_header, true); !s) return s.error();
  if (!have_header) {
    return bad_input(t.source + ":" + std::to_string(line_no + 1) + ": empty file: no header line");
  }
  const std::string_view body = text.substr(std::min(pos, text.size()));

  if (body.size() < kParallelBytes) {
    reserve_rows(t, body);
    std::size_t body_pos = 0;
    if (Status s = parse_lines(body, body_pos, line_no, t, have_header, false); !s) return s.error();
    return t;
  }
  // Two halves split after a newline; the second numbers its lines after the first's. The first
  // error in file order wins, so messages are the same as a sequential parse's.
  const std::size_t split = body.find('\n', body.size() / 2);
  const std::string_view first = body.substr(0, split == std::string_view::npos ? body.size() : split + 1);
  const std::string_view second = body.substr(first.size());
  CsvTable tail;
  tail.source = t.source;
  tail.columns = t.columns;
  tail.header_line = t.header_line;
  tail.text_columns = t.text_columns;
  tail.text_flag = t.text_flag;
  std::size_t tail_line_no = line_no + static_cast<std::size_t>(std::count(first.begin(), first.end(), '\n'));
  Status tail_status = ok_status();
  std::thread worker([&] {
    reserve_rows(tail, second);
    std::size_t tail_pos = 0;
    bool tail_header = true;
    tail_status = parse_lines(second, tail_pos, tail_line_no, tail, tail_header, false);
  });
  reserve_rows(t, body);
  std::size_t head_pos = 0;
  Status head_status = parse_lines(first, head_pos, line_no, t, have_header, false);
  worker.join();
  if (!head_status) return head_status.error();
  if (!tail_status) return tail_status.error();
  t.metadata.insert(t.metadata.end(), tail.metadata.begin(), tail.metadata.end());
  t.comments.insert(t.comments.end(), tail.comments.begin(), tail.comments.end());
  t.cells.insert(t.cells.end(), tail.cells.begin(), tail.cells.end());
  t.empty.insert(t.empty.end(), tail.empty.begin(), tail.empty.end());
  t.lines.insert(t.lines.end(), tail.lines.begin(), tail.lines.end());
  t.rows += tail.rows;
  return t;
}

CsvStreamReader::~CsvStreamReader() {
  if (file_ != nullptr) std::fclose(file_);
}

namespace {
constexpr std::size_t kStreamChunkBytes = std::size_t{1} << 20;
}  // namespace

Status CsvStreamReader::refill() {
  text_.erase(0, pos_);
  pos_ = 0;
  if (text_.size() > kMaxLineBytes) {  // what is left is one unfinished line
    return bad_input(header_.source + ":" + std::to_string(line_no_ + 1) + ": line longer than " +
                     std::to_string(kMaxLineBytes) + " bytes");
  }
  const std::size_t old = text_.size();
  text_.resize(old + kStreamChunkBytes);
  const std::size_t got = std::fread(text_.data() + old, 1, kStreamChunkBytes, file_);
  text_.resize(old + got);
  if (got < kStreamChunkBytes) {
    if (std::ferror(file_) != 0) return failure(header_.source + ": read error");
    eof_ = true;
  }
  return ok_status();
}

Status CsvStreamReader::open(const std::string& path) {
  if (file_ != nullptr || whole_) return failure(path + ": reader already open");
  header_ = CsvTable{};
  header_.source = path;
  if (is_tdms_path(path)) return open_tdms(path);
  if (Status s = check_input(path, kMaxStreamedLogBytes, false); !s) return s;
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) return bad_input(path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(::fileno(file_), &st) == 0 && S_ISREG(st.st_mode))
    total_ = static_cast<std::uint64_t>(st.st_size);
  bool have_header = false;
  bool first = true;
  while (!have_header) {
    if (eof_) {
      return bad_input(header_.source + ":" + std::to_string(line_no_ + 1) + ": empty file: no header line");
    }
    if (Status s = refill(); !s) return s;
    if (first && text_.size() >= 3 && std::memcmp(text_.data(), "\xEF\xBB\xBF", 3) == 0) pos_ = 3;
    first = false;
    // Whole lines only, unless the file ends here.
    const std::size_t last_nl = text_.rfind('\n');
    const std::size_t end =
        eof_ ? text_.size() : (last_nl == std::string::npos || last_nl < pos_ ? pos_ : last_nl + 1);
    const std::string_view whole(text_.data(), end);
    const std::size_t before = pos_;
    if (Status s = parse_lines(whole, pos_, line_no_, header_, have_header, true); !s) return s;
    pos_ = std::min(pos_, end);
    consumed_ += pos_ - before;
  }
  return ok_status();
}

Status CsvStreamReader::open_tdms(const std::string& path) {
  auto table = read_tdms_table(path, TdmsCells::values_only);  // the cells alone: the rows' flags per block
  if (!table) return table.error();
  whole_ = std::make_unique<CsvTable>(std::move(*table));
  header_.metadata = whole_->metadata;
  header_.comments = whole_->comments;
  header_.columns = whole_->columns;
  total_ = whole_->rows;
  return ok_status();
}

// The next rows of a TDMS file's table (bytes_read/bytes_total then count rows).
bool CsvStreamReader::next_tdms_rows(CsvTable& block) {
  constexpr std::size_t kTdmsBlockRows = 65536;
  const std::size_t n = std::min(kTdmsBlockRows, whole_->rows - whole_next_);
  const std::size_t nc = whole_->columns.size();
  const auto first = static_cast<std::ptrdiff_t>(whole_next_ * nc);
  const auto last = static_cast<std::ptrdiff_t>((whole_next_ + n) * nc);
  block.cells.assign(whole_->cells.begin() + first, whole_->cells.begin() + last);
  block.empty.assign(n * nc, 0);  // a TDMS cell is never empty
  block.lines.resize(n);
  for (std::size_t r = 0; r < n; ++r) block.lines[r] = whole_next_ + r + 1;
  block.rows = n;
  whole_next_ += n;
  consumed_ = whole_next_;
  return n > 0;
}

Result<bool> CsvStreamReader::next(CsvTable& block) {
  if (file_ == nullptr && !whole_) return failure("CSV stream reader is not open");
  block.source = header_.source;
  block.metadata = header_.metadata;
  block.comments.clear();
  block.columns = header_.columns;
  block.header_line = header_.header_line;
  block.rows = 0;
  block.cells.clear();
  block.empty.clear();
  block.lines.clear();
  if (whole_) return next_tdms_rows(block);
  bool have_header = true;
  while (true) {
    const std::size_t last_nl = text_.rfind('\n');
    const std::size_t end =
        eof_ ? text_.size() : (last_nl == std::string::npos || last_nl < pos_ ? pos_ : last_nl + 1);
    if (end > pos_) {
      const std::string_view whole(text_.data(), end);
      const std::size_t before = pos_;
      if (Status s = parse_lines(whole, pos_, line_no_, block, have_header, false); !s) return s.error();
      pos_ = std::min(pos_, end);
      consumed_ += pos_ - before;
      if (block.rows > 0) return true;
    }
    if (eof_) return false;
    if (Status s = refill(); !s) return s.error();
  }
}

Result<std::string> read_text_file(const std::string& path) {
  return read_input(path, kMaxTableBytes);
}

Result<CsvTable> read_csv(const std::string& path) {
  if (is_tdms_path(path)) return read_tdms_table(path);
  // A regular file is parsed straight from a read-only mapping: no copy of the text in memory (a
  // 2 h, 100 Hz log is ~45 MB). Anything else (pipes, empty files) is read into a string.
  if (Status st = check_input(path, kMaxTableBytes, false); !st) return st.error();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd >= 0) {
    struct stat st {};
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
      const auto size = static_cast<std::size_t>(st.st_size);
      void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
      ::close(fd);
      if (map != MAP_FAILED) {
        auto table = parse_csv(std::string_view(static_cast<const char*>(map), size), path);
        ::munmap(map, size);
        return table;
      }
    } else {
      ::close(fd);
    }
  }
  auto text = read_text_file(path);
  if (!text) return text.error();
  return parse_csv(*text, path);
}

Status write_text_file(const std::string& path, std::string_view content) {
  RunFiles files;
  if (Status st = files.put(path, "output", content); !st) return st;
  return files.commit();
}

namespace {

// Appends `text` with blanks, controls, ',' and '%' (and, in a key, '=') as %XX: one token of a comment.
void append_escaped(std::string& out, std::string_view text, bool key) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u <= 0x20 || u == 0x7f || c == ',' || c == '%' || (key && c == '=')) {
      out += '%';
      out += kHex[u >> 4U];
      out += kHex[u & 0xFU];
    } else {
      out += c;
    }
  }
}

}  // namespace

void append_metadata(std::string& out, std::string_view key, std::string_view value) {
  out += "# ";
  append_escaped(out, key, true);
  out += '=';
  append_escaped(out, value, false);
  out += '\n';
}

char* format_double(char* first, double value) {
  if (std::isnan(value)) {
    constexpr std::string_view kNan = "nan";
    return std::copy(kNan.begin(), kNan.end(), first);
  }
  return std::to_chars(first, first + kMaxDoubleChars, value).ptr;
}

void append_double(std::string& out, double value) {
  char buf[kMaxDoubleChars];
  out.append(buf, format_double(buf, value));
}

void append_fixed(std::string& out, double value, int decimals) {
  if (std::isnan(value)) {
    out += "nan";
    return;
  }
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed, decimals);
  if (ec != std::errc()) {
    append_double(out, value);
    return;
  }
  out.append(buf, ptr);
}

void append_int(std::string& out, long long value) {
  char buf[24];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, ptr);
}

}  // namespace tetra
