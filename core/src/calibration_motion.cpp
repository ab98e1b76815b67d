// Interpretation of the turntable encoders: which gimbal turns in each sequence, at what rate, at what
// fixed angle of the other gimbal, and the body rate (table + Earth) of every row.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>

#include <Eigen/SVD>

#include "calibration_rows.hpp"
#include "tetra/core/calibration.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/frames.hpp"
#include "tetra/core/units.hpp"
#include "turntable_log_internal.hpp"

namespace tetra {

const char* to_string(CalibrationMethod method) {
  return method == CalibrationMethod::kSixteen ? "sixteen-position" : "batch";
}
const char* to_string(BiasModel model) {
  return model == BiasModel::kBody ? "body" : "seed";
}
const char* to_string(Gimbal gimbal) {
  return gimbal == Gimbal::kInner ? "inner" : "outer";
}

namespace {

//! [deg] angle mapped to (−180, 180].
double wrap180(double angle_deg) {
  double a = std::fmod(angle_deg, 360.0);
  if (a > 180.0) a -= 360.0;
  if (a <= -180.0) a += 360.0;
  return a;
}

std::string fmt(double value, int decimals) {
  std::string s;
  append_fixed(s, value, decimals);
  return s;
}

//! Unwraps one gimbal's angle row by row: range and sum of the unwrapped angle.
struct Unwrapper {
  double first_deg = 0.0;  //!< first encoder reading (= first unwrapped angle)
  double raw_deg = 0.0;    //!< last encoder reading
  double angle_deg = 0.0;  //!< last unwrapped angle
  double lo_deg = 0.0;
  double hi_deg = 0.0;
  double sum_deg = 0.0;
  void start(double a_deg) { first_deg = raw_deg = angle_deg = lo_deg = hi_deg = sum_deg = a_deg; }
  void next(double a_deg) {
    angle_deg = angle_deg + wrap180(a_deg - raw_deg);
    raw_deg = a_deg;
    lo_deg = std::min(lo_deg, angle_deg);
    hi_deg = std::max(hi_deg, angle_deg);
    sum_deg += angle_deg;
  }
  double span_deg() const { return hi_deg - lo_deg; }
};

//! A contiguous block of rows with one sequence number, and what the passes learn about it.
struct Run {
  SequenceMotion m;            //!< sequence, rows, lines, times; the rest once derived
  std::optional<Error> error;  //!< the first of its checks that failed
  Unwrapper inner;             //!< pass 1: both gimbals unwrapped
  Unwrapper outer;
  double time_sum_s = 0.0;
  Eigen::VectorXd g_sum_V;  //!< pass 1: sum of every gyro's output
  Unwrapper turning;        //!< passes 2 and 3: the rotating gimbal, unwrapped again
  double time_mean_s = 0.0;
  double angle_mean_deg = 0.0;
  double stt = 0.0;  //!< pass 2: centred sums of the rate's line fit
  double sta = 0.0;
  double departure_deg = 0.0;  //!< pass 3: largest departure from the line
  Eigen::Vector3d table_sum_dps = Eigen::Vector3d::Zero();
  Eigen::Vector3d earth_sum_dps = Eigen::Vector3d::Zero();
  bool usable() const { return !error.has_value(); }
  double angle_of(const TurntableRow& row) const {
    return m.rotating == Gimbal::kInner ? row.inner_deg : row.outer_deg;
  }
  //! The rotating gimbal's unwrapped angle at `row` (rows visited in order).
  double unwrap_turning(const TurntableRow& row) {
    if (row.index == m.first_row) {
      turning.start(angle_of(row));
    } else {
      turning.next(angle_of(row));
    }
    return turning.angle_deg;
  }
};

std::string lines_of(const std::string& source, const SequenceMotion& m) {
  return source + ":" + std::to_string(m.first_line) + ": sequence " + std::to_string(m.sequence) +
         " (lines " + std::to_string(m.first_line) + "-" + std::to_string(m.last_line) + "): ";
}

//! The runs of the log in file order, with run_of_sequence mapping a sequence to its run.
struct Scan {
  std::vector<Run> runs;
  std::map<int, std::size_t> run_of_sequence;
  std::optional<std::string> error;  //!< a sequence that appears again (the message after the file name)
  double start_time_s = 0.0;
};

//! Pass 1 on one row: a new run or the next row of the current one.
void scan_row(const TurntableRow& row, int gyro_count, Scan& scan) {
  const Eigen::Map<const Eigen::VectorXd> g(row.g_V, gyro_count);
  if (!scan.runs.empty() && scan.runs.back().m.sequence == row.sequence) {
    Run& run = scan.runs.back();
    ++run.m.row_count;
    run.m.last_line = row.line;
    run.inner.next(row.inner_deg);
    run.outer.next(row.outer_deg);
    run.time_sum_s += row.time_s;
    run.g_sum_V += g;
    return;
  }
  if (row.index == 0) scan.start_time_s = row.time_s;
  const auto seen = scan.run_of_sequence.find(row.sequence);
  if (seen != scan.run_of_sequence.end()) {
    if (!scan.error) {
      scan.error = ":" + std::to_string(row.line) + ": sequence " + std::to_string(row.sequence) +
                   " appears again (it ended at line " + std::to_string(scan.runs[seen->second].m.last_line) +
                   "); the rows of a sequence must be contiguous";
    }
    return;
  }
  scan.run_of_sequence[row.sequence] = scan.runs.size();
  Run run;
  run.m.sequence = row.sequence;
  run.m.first_row = row.index;
  run.m.row_count = 1;
  run.m.first_line = run.m.last_line = row.line;
  run.m.first_time_s = row.time_s;
  run.inner.start(row.inner_deg);
  run.outer.start(row.outer_deg);
  run.time_sum_s = row.time_s;
  run.g_sum_V = g;
  scan.runs.push_back(std::move(run));
}

//! Pass 1: the runs (each sequence contiguous), both gimbals unwrapped, the sums of times and outputs.
Result<Scan> scan_runs(const TurntableRows& rows) {
  Scan scan;
  const int n_gyros = rows.gyro_count();
  Status read = rows.for_each([&](const TurntableRow& row) {
    if (!scan.error) scan_row(row, n_gyros, scan);
    if (!scan.runs.empty()) scan.runs.back().m.last_time_s = row.time_s;
  });
  if (!read) return read.error();
  if (scan.error) return bad_input(rows.source() + *scan.error);
  return scan;
}

//! After pass 1: the run's row count and spans checked, its rotating gimbal chosen.
void check_spans(const std::string& source, const TurntableTolerances& tol, Run& run) {
  const std::string where = lines_of(source, run.m);
  if (run.m.row_count < static_cast<std::size_t>(tol.min_rows_per_sequence)) {
    run.error = bad_input(where + "has " + std::to_string(run.m.row_count) + " rows, at least " +
                          std::to_string(tol.min_rows_per_sequence) + " are needed");
    return;
  }
  const double inner_span = run.inner.span_deg();
  const double outer_span = run.outer.span_deg();
  const double moving_span = std::max(inner_span, outer_span);
  const double still_span = std::min(inner_span, outer_span);
  const std::string spans =
      " (inner moves " + fmt(inner_span, 4) + " deg, outer " + fmt(outer_span, 4) + " deg)";
  if (moving_span < tol.min_turn_deg) {
    run.error = bad_input(where + "neither gimbal rotates" + spans +
                          "; a sequence must turn one gimbal at least " + fmt(tol.min_turn_deg, 2) + " deg");
    return;
  }
  if (still_span > tol.fixed_span_deg) {
    run.error = bad_input(where + "both gimbals move" + spans + "; one must stay fixed within " +
                          fmt(tol.fixed_span_deg, 3) + " deg");
    return;
  }
  run.m.rotating = inner_span >= outer_span ? Gimbal::kInner : Gimbal::kOuter;
  const Unwrapper& turning = run.m.rotating == Gimbal::kInner ? run.inner : run.outer;
  const Unwrapper& fixed = run.m.rotating == Gimbal::kInner ? run.outer : run.inner;
  const auto n = static_cast<double>(run.m.row_count);
  run.time_mean_s = run.time_sum_s / n;
  run.angle_mean_deg = turning.sum_deg / n;
  run.m.turned_deg = turning.angle_deg - turning.first_deg;
  run.m.fixed_angle_deg = wrap180(fixed.sum_deg / n);
}

//! The run a row belongs to (rows visited in order; runs in file order).
Run& run_at(std::vector<Run>& runs, std::size_t& cursor, const TurntableRow& row) {
  while (row.index >= runs[cursor].m.first_row + runs[cursor].m.row_count) ++cursor;
  return runs[cursor];
}

//! Pass 2: the rotating gimbal's rate, the least-squares slope of its angle against time (centred).
Status fit_rates(const TurntableRows& rows, std::vector<Run>& runs) {
  std::size_t cursor = 0;
  Status read = rows.for_each([&](const TurntableRow& row) {
    Run& run = run_at(runs, cursor, row);
    if (!run.usable()) return;
    const double angle_deg = run.unwrap_turning(row);
    const double dt = row.time_s - run.time_mean_s;
    run.stt += dt * dt;
    run.sta += dt * (angle_deg - run.angle_mean_deg);
  });
  for (Run& run : runs) {
    if (run.usable()) run.m.rate_dps = run.sta / run.stt;
  }
  return read;
}

//! Pass 3: the angle's departure from its line, and the mean table and Earth rates in B.
Status integrate_rates(const TurntableRows& rows, double latitude_rad, std::vector<Run>& runs) {
  std::size_t cursor = 0;
  Status read = rows.for_each([&](const TurntableRow& row) {
    Run& run = run_at(runs, cursor, row);
    if (!run.usable()) return;
    const double angle_deg = run.unwrap_turning(row);
    const double fit = run.angle_mean_deg + run.m.rate_dps * (row.time_s - run.time_mean_s);
    run.departure_deg = std::max(run.departure_deg, std::abs(angle_deg - fit));
    const calibration_detail::BodyRate w =
        calibration_detail::body_rate(run.m, row.inner_deg, row.outer_deg, latitude_rad);
    run.table_sum_dps += w.table_dps;
    run.earth_sum_dps += w.earth_dps;
  });
  for (Run& run : runs) {
    if (!run.usable()) continue;
    const auto n = static_cast<double>(run.m.row_count);
    run.m.table_rate_B_dps = run.table_sum_dps / n;
    run.m.earth_rate_B_dps = run.earth_sum_dps / n;
  }
  return read;
}

//! After pass 3: a rotating gimbal that does not turn at a constant rate.
void check_departure(const std::string& source, const TurntableTolerances& tol, Run& run) {
  if (!run.usable() || run.departure_deg <= tol.max_rate_departure_deg) return;
  run.error =
      bad_input(lines_of(source, run.m) + "the " + to_string(run.m.rotating) +
                " gimbal does not turn at a constant rate (its angle departs " + fmt(run.departure_deg, 3) +
                " deg from a straight line, tolerance " + fmt(tol.max_rate_departure_deg, 3) + " deg)");
}

//! The sequences in plan order with their mean outputs; the first error in plan order.
Status collect_sequences(const Scan& scan, TurntableMotion& motion) {
  const auto n_gyros = scan.runs.front().g_sum_V.size();
  motion.g_mean_V.resize(static_cast<Eigen::Index>(scan.runs.size()), n_gyros);
  for (const auto& [sequence, index] : scan.run_of_sequence) {  // plan order
    const Run& run = scan.runs[index];
    if (run.error) return *run.error;
    const auto j = static_cast<Eigen::Index>(motion.sequences.size());
    motion.g_mean_V.row(j) = (run.g_sum_V / static_cast<double>(run.m.row_count)).transpose();
    motion.sequences.push_back(run.m);
  }
  return ok_status();
}

//! Pairs (2k−1, 2k): both present, same gimbal, opposite rates, same fixed angle.
Status check_pairs(const std::string& source, const Scan& scan, const TurntableMotion& motion,
                   const TurntableTolerances& tolerances) {
  for (const SequenceMotion& m : motion.sequences) {
    const int partner = m.sequence % 2 == 1 ? m.sequence + 1 : m.sequence - 1;
    if (scan.run_of_sequence.count(partner) == 0) {
      return bad_input(lines_of(source, m) + "has no pair: sequence " + std::to_string(partner) +
                       " is missing (sequences 2k-1 and 2k are opposite rotations of the same gimbal)");
    }
  }
  for (std::size_t p = 0; p + 1 < motion.sequences.size(); p += 2) {
    const SequenceMotion& a = motion.sequences[p];
    const SequenceMotion& b = motion.sequences[p + 1];
    const std::string where =
        lines_of(source, b) + "pairs with sequence " + std::to_string(a.sequence) + " but ";
    if (a.rotating != b.rotating) {
      return bad_input(where + "turns the " + to_string(b.rotating) + " gimbal where sequence " +
                       std::to_string(a.sequence) + " turns the " + to_string(a.rotating) + " gimbal");
    }
    if ((a.rate_dps > 0) == (b.rate_dps > 0)) {
      return bad_input(where + "turns in the same direction (" + fmt(b.rate_dps, 4) + " deg/s vs " +
                       fmt(a.rate_dps, 4) + " deg/s); a pair needs opposite rotations");
    }
    const double mismatch = std::abs(wrap180(a.fixed_angle_deg - b.fixed_angle_deg));
    if (mismatch > tolerances.pair_angle_match_deg) {
      return bad_input(where + "holds the other gimbal at " + fmt(b.fixed_angle_deg, 4) + " deg instead of " +
                       fmt(a.fixed_angle_deg, 4) + " deg");
    }
  }
  return ok_status();
}

//! The pair differences must excite three independent body axes.
Status check_excitation(const std::string& source, const TurntableMotion& motion) {
  const std::size_t pairs = motion.sequences.size() / 2;
  Eigen::MatrixXd diff(static_cast<Eigen::Index>(pairs), 3);
  for (std::size_t p = 0; p < pairs; ++p) {
    diff.row(static_cast<Eigen::Index>(p)) =
        (motion.sequences[2 * p].rate_B_dps() - motion.sequences[2 * p + 1].rate_B_dps()).transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(diff);
  const auto& sv = svd.singularValues();
  if (pairs < 3 || sv(2) < 1e-3 * sv(0)) {
    int rank = 0;
    for (Eigen::Index k = 0; k < sv.size(); ++k) rank += sv(k) >= 1e-3 * sv(0) ? 1 : 0;
    return bad_input(
        source + ": the " + std::to_string(pairs) + " sequence pairs excite only " + std::to_string(rank) +
        " independent body axes; the rotation plan needs rotations about three (e.g. seed Table 3)");
  }
  return ok_status();
}

}  // namespace

namespace calibration_detail {

BodyRate body_rate(const SequenceMotion& m, double inner_deg, double outer_deg, double latitude_rad) {
  const double inner_dot_rad_s = m.rotating == Gimbal::kInner ? m.rate_dps * kDegToRad : 0.0;
  const double outer_dot_rad_s = m.rotating == Gimbal::kOuter ? m.rate_dps * kDegToRad : 0.0;
  const double inner_rad = inner_deg * kDegToRad;
  const double outer_rad = outer_deg * kDegToRad;
  return {turntable_rate_B(inner_rad, inner_dot_rad_s, outer_dot_rad_s) * kRadToDeg,
          turntable_earth_rate_B(inner_rad, outer_rad, latitude_rad) * kRadToDeg};
}

namespace {

constexpr std::size_t kRateBlockRows = 1024;  // rates written or read back at a time

// Appends rates to the cache a block at a time; marks it failed (and unused) when it cannot write.
class RateWriter {
 public:
  explicit RateWriter(BodyRateCache* cache) : cache_(cache) {
    if (cache_ == nullptr || cache_->failed) return;
    if (cache_->file != nullptr) {  // an earlier pass stopped part way: its rates are not all there
      cache_->failed = true;
      return;
    }
    auto file = turntable_detail::open_temporary_file("the body rates");
    if (file) {
      cache_->file = *file;
    } else {
      cache_->failed = true;
    }
  }
  bool active() const { return cache_ != nullptr && !cache_->failed && cache_->file != nullptr; }
  void add(const Eigen::Vector3d& w) {
    buffer_.insert(buffer_.end(), w.data(), w.data() + 3);
    if (buffer_.size() == 3 * kRateBlockRows) flush();
  }
  void finish() {
    flush();
    if (active() && std::fflush(cache_->file) == 0) cache_->ready = true;
  }

 private:
  void flush() {
    if (active() &&
        std::fwrite(buffer_.data(), sizeof(double), buffer_.size(), cache_->file) != buffer_.size()) {
      cache_->failed = true;
    }
    buffer_.clear();
  }
  BodyRateCache* cache_;
  std::vector<double> buffer_;
};

// Moves `cursor` to the sequence (index into file_order) that holds `row`.
void advance(const TurntableMotion& motion, const std::vector<std::size_t>& file_order,
             const TurntableRow& row, std::size_t& cursor) {
  while (cursor + 1 < file_order.size() && row.index >= motion.sequences[file_order[cursor + 1]].first_row) {
    ++cursor;
  }
}

// The cached rates read back beside the rows.
Status replay_rates(const TurntableRows& rows, const std::vector<std::size_t>& file_order,
                    const TurntableMotion& motion, BodyRateCache& cache, const RateRowVisitor& visit) {
  if (std::fseek(cache.file, 0, SEEK_SET) != 0)
    return failure(rows.source() + ": cannot read the body rates again");
  std::vector<double> buffer(3 * kRateBlockRows);
  std::size_t held = 0;
  std::size_t next = 0;
  bool short_read = false;
  std::size_t cursor = 0;
  Status read = rows.for_each([&](const TurntableRow& row) {
    if (short_read) return;
    if (next == held) {
      const std::size_t want = std::min(kRateBlockRows, rows.rows() - row.index);
      held = std::fread(buffer.data(), 3 * sizeof(double), want, cache.file);
      next = 0;
      if (held != want) {
        short_read = true;
        return;
      }
    }
    advance(motion, file_order, row, cursor);
    const Eigen::Vector3d w(buffer[3 * next], buffer[3 * next + 1], buffer[3 * next + 2]);
    ++next;
    visit(row, file_order[cursor], w);
  });
  if (!read) return read;
  if (short_read)
    return failure(rows.source() + ": cannot read the body rates again from the temporary file");
  return ok_status();
}

}  // namespace

Status for_each_rate_row(const TurntableRows& rows, const TurntableMotion& motion,
                         const RateRowVisitor& visit) {
  std::vector<std::size_t> file_order(motion.sequences.size());
  for (std::size_t j = 0; j < file_order.size(); ++j) file_order[j] = j;
  std::sort(file_order.begin(), file_order.end(), [&](std::size_t a, std::size_t b) {
    return motion.sequences[a].first_row < motion.sequences[b].first_row;
  });
  BodyRateCache* cache = motion.rate_cache.get();
  if (cache != nullptr && cache->ready) return replay_rates(rows, file_order, motion, *cache, visit);
  RateWriter writer(cache);
  const double latitude_rad = motion.latitude_deg * kDegToRad;
  std::size_t cursor = 0;
  Status read = rows.for_each([&](const TurntableRow& row) {
    advance(motion, file_order, row, cursor);
    const std::size_t j = file_order[cursor];
    const Eigen::Vector3d w =
        body_rate(motion.sequences[j], row.inner_deg, row.outer_deg, latitude_rad).total_dps();
    if (writer.active()) writer.add(w);
    visit(row, j, w);
  });
  if (!read) return read;
  writer.finish();
  return ok_status();
}

}  // namespace calibration_detail

Result<TurntableMotion> analyze_turntable(const TurntableRows& rows, double latitude_deg,
                                          const TurntableTolerances& tolerances) {
  if (!std::isfinite(latitude_deg) || std::abs(latitude_deg) > 90.0) {
    return bad_input(rows.source() + ": latitude " + fmt(latitude_deg, 6) + " deg is outside [-90, 90]");
  }
  if (rows.rows() == 0) return bad_input(rows.source() + ": no data rows");
  if (rows.gyro_count() < 1) return failure(rows.source() + ": inconsistent turntable log (no gyros)");
  auto scan = scan_runs(rows);
  if (!scan) return scan.error();
  for (Run& run : scan->runs) check_spans(rows.source(), tolerances, run);
  if (Status s = fit_rates(rows, scan->runs); !s) return s.error();
  if (Status s = integrate_rates(rows, latitude_deg * kDegToRad, scan->runs); !s) return s.error();
  for (Run& run : scan->runs) check_departure(rows.source(), tolerances, run);
  TurntableMotion motion;
  motion.source = rows.source();
  motion.latitude_deg = latitude_deg;
  motion.rows = rows.rows();
  motion.start_time_s = scan->start_time_s;
  motion.rate_cache = std::make_shared<BodyRateCache>();
  if (Status s = collect_sequences(*scan, motion); !s) return s.error();
  if (Status s = check_pairs(rows.source(), *scan, motion, tolerances); !s) return s.error();
  if (Status s = check_excitation(rows.source(), motion); !s) return s.error();
  return motion;
}

Result<TurntableMotion> analyze_turntable(const TurntableLog& log, double latitude_deg,
                                          const TurntableTolerances& tolerances) {
  const std::size_t rows = log.rows();
  if (log.gyro_count < 1 || log.sequence.size() != rows || log.inner_deg.size() != rows ||
      log.outer_deg.size() != rows || log.g_V.size() != rows * static_cast<std::size_t>(log.gyro_count)) {
    if (rows != 0 && std::isfinite(latitude_deg) && std::abs(latitude_deg) <= 90.0)
      return failure(log.source + ": inconsistent turntable log (column lengths differ)");
  }
  return analyze_turntable(TurntableLogRows(log), latitude_deg, tolerances);
}

}  // namespace tetra
