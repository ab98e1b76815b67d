// Turntable logs visited in passes: a log in memory, or a file spilled once into a temporary binary file.
#include "tetra/core/turntable_rows.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "tetra/core/input_files.hpp"
#include "turntable_log_internal.hpp"

namespace tetra {

namespace {

constexpr std::size_t kFixedFields = 5;       // line, sequence, time_s, inner_deg, outer_deg
constexpr std::size_t kPassBlockRows = 1024;  // rows read back at a time

std::size_t record_size(int gyro_count) {
  return kFixedFields + static_cast<std::size_t>(gyro_count);
}

// The record of row `r` of a checked block: line, sequence, time, angles, gyro outputs.
void append_record(const CsvTable& t, const turntable_detail::Columns& c, std::size_t r,
                   std::vector<double>& out) {
  out.push_back(static_cast<double>(t.lines[r]));
  for (const std::size_t col : c.fixed) out.push_back(t.cell(r, col));
  for (const std::size_t col : c.gyro) out.push_back(t.cell(r, col));
}

}  // namespace

namespace turntable_detail {

Result<std::FILE*> open_temporary_file(const std::string& what) {
  const char* env = std::getenv("TMPDIR");
  const std::string dir = env != nullptr && *env != '\0' ? env : "/tmp";
  std::string templ = dir + "/tetra-turntable-XXXXXX";
  const int fd = ::mkostemp(templ.data(), O_CLOEXEC);
  if (fd < 0) {
    return failure(dir + ": cannot create a temporary file for " + what + " (" + std::strerror(errno) +
                   "; TMPDIR names another folder)");
  }
  ::unlink(templ.c_str());
  std::FILE* f = ::fdopen(fd, "w+b");
  if (f == nullptr) {
    ::close(fd);
    return failure(dir + ": cannot open a temporary file for " + what);
  }
  return f;
}

}  // namespace turntable_detail

Status TurntableLogRows::for_each(const TurntableRowVisitor& visit) const {
  const auto ng = static_cast<std::size_t>(log_.gyro_count);
  TurntableRow row;
  for (std::size_t r = 0; r < log_.rows(); ++r) {
    row.index = r;
    row.line = r < log_.lines.size() ? log_.lines[r] : r + 1;
    row.sequence = log_.sequence[r];
    row.time_s = log_.time_s[r];
    row.inner_deg = log_.inner_deg[r];
    row.outer_deg = log_.outer_deg[r];
    row.g_V = log_.g_V.data() + r * ng;
    visit(row);
  }
  return ok_status();
}

TurntableFileRows::~TurntableFileRows() {
  if (spill_ != nullptr) std::fclose(spill_);
}

// Every block checked as read_turntable_log checks it, then appended to the temporary file.
Status TurntableFileRows::spill_rows(CsvStreamReader& reader, std::size_t header_entries) {
  auto columns = turntable_detail::find_columns(reader.header());
  if (!columns) return columns.error();
  gyro_count_ = static_cast<int>(columns->gyro.size());
  CsvTable block;
  std::vector<double> records;
  double last_time_s = 0.0;
  while (true) {
    auto more = reader.next(block);
    if (!more) return more.error();
    turntable_detail::append_block_metadata(block, header_entries, metadata_);
    if (!*more) return ok_status();
    records.clear();
    for (std::size_t r = 0; r < block.rows; ++r) {
      if (Status s = turntable_detail::check_row(block, *columns, r, rows_ == 0 ? nullptr : &last_time_s); !s)
        return s;
      last_time_s = block.cell(r, columns->fixed[1]);
      append_record(block, *columns, r, records);
      ++rows_;
    }
    if (std::fwrite(records.data(), sizeof(double), records.size(), spill_) != records.size()) {
      return failure(source_ + ": cannot write its rows to a temporary file (disk full?)");
    }
  }
}

Status TurntableFileRows::open(const std::string& path) {
  source_ = path;
  if (Status s = check_input(path, kMaxStreamedLogBytes, false); !s) return s;
  CsvStreamReader reader;
  if (Status s = reader.open(path); !s) return s;
  metadata_ = reader.header().metadata;
  auto spill = turntable_detail::open_temporary_file("the turntable rows");
  if (!spill) return spill.error();
  spill_ = *spill;
  if (Status s = spill_rows(reader, metadata_.size()); !s) return s;
  if (rows_ == 0) return bad_input(source_ + ": no data rows");
  if (std::fflush(spill_) != 0) return failure(source_ + ": cannot write its rows to a temporary file");
  return ok_status();
}

Status TurntableFileRows::for_each(const TurntableRowVisitor& visit) const {
  const std::size_t width = record_size(gyro_count_);
  std::vector<double> records(kPassBlockRows * width);
  if (std::fseek(spill_, 0, SEEK_SET) != 0) return failure(source_ + ": cannot read its rows again");
  TurntableRow row;
  for (std::size_t first = 0; first < rows_; first += kPassBlockRows) {
    const std::size_t n = std::min(kPassBlockRows, rows_ - first);
    if (std::fread(records.data(), sizeof(double) * width, n, spill_) != n) {
      return failure(source_ + ": cannot read its rows again from the temporary file");
    }
    for (std::size_t k = 0; k < n; ++k) {
      const double* rec = records.data() + k * width;
      row.index = first + k;
      row.line = static_cast<std::size_t>(rec[0]);
      row.sequence = static_cast<int>(rec[1]);
      row.time_s = rec[2];
      row.inner_deg = rec[3];
      row.outer_deg = rec[4];
      row.g_V = rec + kFixedFields;
      visit(row);
    }
  }
  return ok_status();
}

}  // namespace tetra
