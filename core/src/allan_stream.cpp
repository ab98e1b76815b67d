// analyze_gyro_log_file: the Allan analysis of a log read block by block, in about 14 bytes per sample.
//
// Memory, per epoch of N gyros analysed: the rates, 8·N bytes (a double per sample; NaN where absent or
// invalid), in chunks while reading, each gyro's chunks then moved one by one into one array that
// becomes the cumulative sum in place; the times, 8 bytes, freed once the grid is built; the grid slots,
// 8 bytes; the cumulative count of present samples, 4 bytes per gyro being analysed, only when samples
// are missing. With N = 4 that is 8 + 4 + 2 (+ 2) bytes per sample at the peak. Every large block is an
// anonymous mapping unmapped when consumed, so freed memory goes back to the system at once.
#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <new>
#include <optional>
#include <thread>
#include <utility>

#include "allan_internal.hpp"
#include "tetra/core/allan.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/gyro_log_prefetch.hpp"
#include "tetra/core/units.hpp"

namespace tetra::allan {

namespace {

// A fixed-size array in its own anonymous mapping; pages are committed as they are written.
template <class T>
class MappedArray {
 public:
  MappedArray() = default;
  explicit MappedArray(std::size_t n) : size_(n) {
    if (n == 0) return;
    void* p = ::mmap(nullptr, n * sizeof(T), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) {
      size_ = 0;
      return;
    }
    ::madvise(p, n * sizeof(T), MADV_HUGEPAGE);  // fewer page faults where the system allows it
    data_ = static_cast<T*>(p);
  }
  MappedArray(const MappedArray&) = delete;
  MappedArray& operator=(const MappedArray&) = delete;
  MappedArray(MappedArray&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)) {}
  MappedArray& operator=(MappedArray&& o) noexcept {
    if (this != &o) {
      reset();
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
    }
    return *this;
  }
  ~MappedArray() { reset(); }
  void reset() {
    if (data_ != nullptr) ::munmap(data_, size_ * sizeof(T));
    data_ = nullptr;
    size_ = 0;
  }
  bool ok(std::size_t wanted) const { return wanted == 0 || data_ != nullptr; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0;
};

// A column of doubles that grows by 2 MB chunks (no reallocation, no copy while reading).
class ChunkedColumn {
 public:
  static constexpr std::size_t kChunk = std::size_t{1} << 18;
  bool push_back(double v) {
    if (size_ % kChunk == 0) {
      chunks_.emplace_back(kChunk);
      if (!chunks_.back().ok(kChunk)) return false;
    }
    chunks_[size_ / kChunk][size_ % kChunk] = v;
    ++size_;
    return true;
  }
  std::size_t size() const { return size_; }
  double at(std::size_t i) const { return chunks_[i / kChunk][i % kChunk]; }
  //! Frees the chunk holding element i (call once past its last element).
  void release_chunk_of(std::size_t i) { chunks_[i / kChunk].reset(); }

 private:
  std::vector<MappedArray<double>> chunks_;
  std::size_t size_ = 0;
};

// What the reading pass keeps.
struct StreamColumns {
  GyroLog header;
  ChunkedColumn time_s;
  std::vector<std::pair<std::size_t, std::size_t>> line_breaks;  // (row, line) where line != previous + 1
  std::vector<int> ids;                                          // gyros stored, sorted
  std::vector<ChunkedColumn> rate;                               // per stored gyro: NaN = not usable
  std::vector<std::size_t> invalid;                              // per stored gyro: delivered NaN/inf
  std::vector<std::size_t> delivered;                            // per stored gyro: finite samples

  std::optional<std::size_t> line_of(std::size_t row) const {
    auto it = std::upper_bound(line_breaks.begin(), line_breaks.end(), std::make_pair(row, SIZE_MAX));
    if (it == line_breaks.begin()) return std::nullopt;
    --it;
    return it->second + (row - it->first);
  }
};

Error out_of_memory(const std::string& source) {
  return failure(source + ": out of memory for the Allan analysis (about 14 bytes per sample)");
}

// Reads the log once, keeping the times and each wanted gyro's rate (calibrated when asked).
Status read_columns(GyroLogPrefetcher& reader, const LogAllanOptions& options, bool calibrate,
                    StreamColumns& c) {
  const auto ng = static_cast<std::size_t>(c.header.gyro_count);
  c.rate.resize(c.ids.size());
  c.invalid.assign(c.ids.size(), 0);
  c.delivered.assign(c.ids.size(), 0);
  std::vector<double> bias(c.ids.size(), 0.0);
  std::vector<double> scale(c.ids.size(), 1.0);
  for (std::size_t j = 0; j < c.ids.size() && calibrate; ++j) {
    const GyroCalibration& cal = options.calibration->gyros[static_cast<std::size_t>(c.ids[j] - 1)];
    bias[j] = cal.bias_V;
    scale[j] = cal.scale_factor_V_per_dps;
  }
  GyroLog block;
  std::size_t row = 0;
  std::size_t expected_line = 0;
  while (true) {
    auto more = reader.next(block);
    if (!more) return more.error();
    if (!*more) return ok_status();
    for (std::size_t k = 0; k < block.epochs(); ++k, ++row) {
      if (row == 0 || block.lines[k] != expected_line) c.line_breaks.emplace_back(row, block.lines[k]);
      expected_line = block.lines[k] + 1;
      if (!c.time_s.push_back(block.time_s[k])) return out_of_memory(c.header.source);
      for (std::size_t j = 0; j < c.ids.size(); ++j) {
        const std::size_t g = static_cast<std::size_t>(c.ids[j] - 1);
        double v = kNaN;
        if (block.present[k * ng + g] != 0) {
          v = block.values[k * ng + g];
          if (std::isfinite(v)) {
            ++c.delivered[j];
            v = calibrate ? (v - bias[j]) / scale[j] : v;
          } else {
            ++c.invalid[j];
            v = kNaN;
          }
        }
        if (!c.rate[j].push_back(v)) return out_of_memory(c.header.source);
      }
    }
  }
}

// One gyro on the grid: rates placed in their slots, then the cumulative sum in place and the analysis,
// by the same operations as overlapping_avar and analyze_series.
Result<AllanResult> analyse_column(ChunkedColumn& column, const SamplingGrid& grid,
                                   const AllanOptions& options, const std::string& source) {
  if (Status st = check_series_options(grid.tau0_s, options); !st) return st.error();
  const std::size_t n = grid.slots;
  MappedArray<double> x(n + 1);  // x[i + 1] holds rate i, then the angle
  if (!x.ok(n + 1)) return out_of_memory(source);
  std::size_t next_slot = 0;
  for (std::size_t r = 0; r < column.size(); ++r) {
    for (; next_slot < grid.slot[r]; ++next_slot) x[next_slot + 1] = kNaN;
    x[next_slot + 1] = column.at(r);
    ++next_slot;
    if ((r + 1) % ChunkedColumn::kChunk == 0 || r + 1 == column.size()) column.release_chunk_of(r);
  }
  // Present count, runs and mean in one pass (a NaN rate is a sample not present).
  std::size_t count = 0;
  std::vector<std::size_t> runs;
  std::size_t run = 0;
  long double mean_acc = 0.0L;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = x[i + 1];
    if (std::isfinite(v)) {
      mean_acc += v;
      ++count;
      ++run;
    } else if (run > 0) {
      runs.push_back(run);
      run = 0;
    }
  }
  if (run > 0) runs.push_back(run);
  if (Status st = check_present_samples(count); !st) return st.error();
  auto ms = averaging_factors(options.taus, n, grid.tau0_s);
  if (!ms) return ms.error();
  const double mean = static_cast<double>(mean_acc / static_cast<long double>(count));
  const bool complete = count == n;
  MappedArray<std::uint32_t> cum(complete ? 0 : n + 1);
  if (!cum.ok(complete ? 0 : n + 1)) return out_of_memory(source);
  long double acc = 0.0L;
  std::uint32_t c = 0;
  x[0] = 0.0;
  if (!complete) cum[0] = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = x[i + 1];
    if (std::isfinite(v)) {
      acc += static_cast<long double>(v - mean);
      ++c;
    }
    x[i + 1] = static_cast<double>(acc);
    if (!complete) cum[i + 1] = c;
  }
  const std::vector<AvarPoint> all =
      avar_from_angle(x.data(), complete ? nullptr : cum.data(), n, grid.tau0_s, *ms);
  return finish_series(n, count, all, runs, grid.tau0_s, options);
}

}  // namespace

Result<LogAllan> analyze_gyro_log_file(const std::string& path, const LogAllanOptions& options) {
  auto reader = GyroLogReader::open(path);
  if (!reader) return reader.error();
  StreamColumns c;
  c.header = (*reader)->header();
  const GyroLog& log = c.header;
  const bool calibrate = !log.units_dps && options.calibration != nullptr;
  // Only valid ids are kept while reading; a bad one is reported after the reading, in the order of
  // analyze_gyro_log (which runs after the whole log has been read).
  const auto ids = gyro_ids(options, log.gyro_count);
  const bool cal_short = calibrate && options.calibration->gyro_count() < log.gyro_count;
  if (ids && !cal_short) c.ids = *ids;
  {
    GyroLogPrefetcher prefetch(std::move(reader.value()));  // parsing overlaps storing the columns
    if (Status st = read_columns(prefetch, options, calibrate, c); !st) return st.error();
  }

  LogAllan out;
  out.epochs = c.time_s.size();
  out.units = (log.units_dps || calibrate) ? "deg/s" : "V";
  out.log_units_dps = log.units_dps;
  if (cal_short) {
    return bad_input(log.source + ": the log has " + std::to_string(log.gyro_count) +
                     " gyros but the calibration only " + std::to_string(options.calibration->gyro_count()));
  }
  if (!ids) return ids.error();
  std::optional<SamplingGrid> grid;
  {
    MappedArray<double> time(out.epochs);
    if (!time.ok(out.epochs)) return out_of_memory(log.source);
    for (std::size_t r = 0; r < out.epochs; ++r) {
      time[r] = c.time_s.at(r);
      if ((r + 1) % ChunkedColumn::kChunk == 0 || r + 1 == out.epochs) c.time_s.release_chunk_of(r);
    }
    auto g = uniform_grid_lines(std::span<const double>(time.data(), out.epochs), options.dt_tolerance,
                                log.source, [&](std::size_t row) { return c.line_of(row); });
    if (!g) return g.error();
    grid = std::move(g.value());
  }
  out.tau0_s = grid->tau0_s;
  out.missing_epochs = grid->missing_epochs;

  auto analyse_one = [&](std::size_t j) -> Result<GyroAllan> {
    auto r = analyse_column(c.rate[j], *grid, without_interrupt(options.allan), log.source);
    if (!r) return gyro_error(r.error(), log.source, c.ids[j], c.ids.size());
    GyroAllan gyro;
    gyro.id = c.ids[j];
    gyro.invalid = c.invalid[j];
    gyro.absent = grid->slots - c.delivered[j] - c.invalid[j];
    gyro.result = std::move(r.value());
    return gyro;
  };
  if (Status st = analyse_gyros(c.ids.size(), analyse_one, out.gyros); !st) return st.error();
  return out;
}

}  // namespace tetra::allan
