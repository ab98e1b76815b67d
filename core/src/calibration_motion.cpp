// Interpretation of the turntable encoders: which gimbal turns in each sequence, at what rate, at what
// fixed angle of the other gimbal, and the body rate (table + Earth) of every row.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include <Eigen/SVD>

#include "tetra/core/calibration.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/frames.hpp"
#include "tetra/core/units.hpp"

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

//! 1-based file line of a row; logs built in memory (no file lines) count rows from 1.
std::size_t line_of(const TurntableLog& log, std::size_t row) {
  return row < log.lines.size() ? log.lines[row] : row + 1;
}

//! A contiguous block of rows with one sequence number.
struct Run {
  int sequence = 0;
  std::size_t first = 0;
  std::size_t count = 0;
};

struct Unwrapped {
  std::vector<double> angle_deg;
  double span_deg = 0.0;  //!< max − min
};

Unwrapped unwrap(const std::vector<double>& angle_deg, std::size_t first, std::size_t count) {
  Unwrapped u;
  u.angle_deg.resize(count);
  u.angle_deg[0] = angle_deg[first];
  double lo = u.angle_deg[0];
  double hi = u.angle_deg[0];
  for (std::size_t k = 1; k < count; ++k) {
    u.angle_deg[k] = u.angle_deg[k - 1] + wrap180(angle_deg[first + k] - angle_deg[first + k - 1]);
    lo = std::min(lo, u.angle_deg[k]);
    hi = std::max(hi, u.angle_deg[k]);
  }
  u.span_deg = hi - lo;
  return u;
}

std::string lines_of(const TurntableLog& log, const SequenceMotion& m) {
  return log.source + ":" + std::to_string(m.first_line) + ": sequence " + std::to_string(m.sequence) +
         " (lines " + std::to_string(m.first_line) + "-" + std::to_string(m.last_line) + "): ";
}

//! Derives the motion of one run; fills the per-row body rates.
Result<SequenceMotion> analyze_run(const TurntableLog& log, const Run& run, double latitude_rad,
                                   const TurntableTolerances& tol, std::vector<Eigen::Vector3d>& rate_B_dps) {
  SequenceMotion m;
  m.sequence = run.sequence;
  m.first_row = run.first;
  m.row_count = run.count;
  m.first_line = line_of(log, run.first);
  m.last_line = line_of(log, run.first + run.count - 1);
  const std::string where = lines_of(log, m);
  if (run.count < static_cast<std::size_t>(tol.min_rows_per_sequence)) {
    return bad_input(where + "has " + std::to_string(run.count) + " rows, at least " +
                     std::to_string(tol.min_rows_per_sequence) + " are needed");
  }
  const Unwrapped inner = unwrap(log.inner_deg, run.first, run.count);
  const Unwrapped outer = unwrap(log.outer_deg, run.first, run.count);
  const double moving_span = std::max(inner.span_deg, outer.span_deg);
  const double still_span = std::min(inner.span_deg, outer.span_deg);
  const std::string spans =
      " (inner moves " + fmt(inner.span_deg, 4) + " deg, outer " + fmt(outer.span_deg, 4) + " deg)";
  if (moving_span < tol.min_turn_deg) {
    return bad_input(where + "neither gimbal rotates" + spans +
                     "; a sequence must turn one gimbal at least " + fmt(tol.min_turn_deg, 2) + " deg");
  }
  if (still_span > tol.fixed_span_deg) {
    return bad_input(where + "both gimbals move" + spans + "; one must stay fixed within " +
                     fmt(tol.fixed_span_deg, 3) + " deg");
  }
  m.rotating = inner.span_deg >= outer.span_deg ? Gimbal::kInner : Gimbal::kOuter;
  const Unwrapped& turning = m.rotating == Gimbal::kInner ? inner : outer;
  const Unwrapped& fixed = m.rotating == Gimbal::kInner ? outer : inner;

  // Rate: least-squares slope of the unwrapped angle against time (centred for conditioning).
  const std::size_t n = run.count;
  double t_mean = 0.0;
  double a_mean = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    t_mean += log.time_s[run.first + k];
    a_mean += turning.angle_deg[k];
  }
  t_mean /= static_cast<double>(n);
  a_mean /= static_cast<double>(n);
  double stt = 0.0;
  double sta = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double dt = log.time_s[run.first + k] - t_mean;
    stt += dt * dt;
    sta += dt * (turning.angle_deg[k] - a_mean);
  }
  m.rate_dps = sta / stt;
  double departure = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double fit = a_mean + m.rate_dps * (log.time_s[run.first + k] - t_mean);
    departure = std::max(departure, std::abs(turning.angle_deg[k] - fit));
  }
  if (departure > tol.max_rate_departure_deg) {
    return bad_input(where + "the " + to_string(m.rotating) +
                     " gimbal does not turn at a constant rate (its angle departs " + fmt(departure, 3) +
                     " deg from a straight line, tolerance " + fmt(tol.max_rate_departure_deg, 3) + " deg)");
  }
  m.turned_deg = turning.angle_deg[n - 1] - turning.angle_deg[0];
  double fixed_sum = 0.0;
  for (double a : fixed.angle_deg) fixed_sum += a;
  m.fixed_angle_deg = wrap180(fixed_sum / static_cast<double>(n));

  const double inner_dot_rad_s = m.rotating == Gimbal::kInner ? m.rate_dps * kDegToRad : 0.0;
  const double outer_dot_rad_s = m.rotating == Gimbal::kOuter ? m.rate_dps * kDegToRad : 0.0;
  Eigen::Vector3d table_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d earth_sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t row = run.first + k;
    const double inner_rad = log.inner_deg[row] * kDegToRad;
    const double outer_rad = log.outer_deg[row] * kDegToRad;
    const Eigen::Vector3d table_dps =
        turntable_rate_B(inner_rad, inner_dot_rad_s, outer_dot_rad_s) * kRadToDeg;
    const Eigen::Vector3d earth_dps = turntable_earth_rate_B(inner_rad, outer_rad, latitude_rad) * kRadToDeg;
    table_sum += table_dps;
    earth_sum += earth_dps;
    rate_B_dps[row] = table_dps + earth_dps;
  }
  m.table_rate_B_dps = table_sum / static_cast<double>(n);
  m.earth_rate_B_dps = earth_sum / static_cast<double>(n);
  return m;
}

}  // namespace

Result<TurntableMotion> analyze_turntable(const TurntableLog& log, double latitude_deg,
                                          const TurntableTolerances& tolerances) {
  if (!std::isfinite(latitude_deg) || std::abs(latitude_deg) > 90.0) {
    return bad_input(log.source + ": latitude " + fmt(latitude_deg, 6) + " deg is outside [-90, 90]");
  }
  if (log.rows() == 0) return bad_input(log.source + ": no data rows");
  const std::size_t rows = log.rows();
  if (log.gyro_count < 1 || log.sequence.size() != rows || log.inner_deg.size() != rows ||
      log.outer_deg.size() != rows || log.g_V.size() != rows * static_cast<std::size_t>(log.gyro_count)) {
    return failure(log.source + ": inconsistent turntable log (column lengths differ)");
  }
  TurntableMotion motion;
  motion.source = log.source;
  motion.latitude_deg = latitude_deg;
  motion.rate_B_dps.assign(log.rows(), Eigen::Vector3d::Zero());

  // Contiguous runs; a sequence number may not come back after another one.
  std::vector<Run> runs;
  std::map<int, std::size_t> run_of_sequence;
  for (std::size_t r = 0; r < log.rows(); ++r) {
    if (!runs.empty() && runs.back().sequence == log.sequence[r]) {
      ++runs.back().count;
      continue;
    }
    const auto seen = run_of_sequence.find(log.sequence[r]);
    if (seen != run_of_sequence.end()) {
      const Run& earlier = runs[seen->second];
      return bad_input(log.source + ":" + std::to_string(line_of(log, r)) + ": sequence " +
                       std::to_string(log.sequence[r]) + " appears again (it ended at line " +
                       std::to_string(line_of(log, earlier.first + earlier.count - 1)) +
                       "); the rows of a sequence must be contiguous");
    }
    run_of_sequence[log.sequence[r]] = runs.size();
    runs.push_back(Run{log.sequence[r], r, 1});
  }

  const double latitude_rad = latitude_deg * kDegToRad;
  for (const auto& [sequence, index] : run_of_sequence) {  // plan order
    auto m = analyze_run(log, runs[index], latitude_rad, tolerances, motion.rate_B_dps);
    if (!m) return m.error();
    motion.sequences.push_back(std::move(m.value()));
  }

  // Pairs (2k−1, 2k): both present, same gimbal, opposite rates, same fixed angle.
  for (const SequenceMotion& m : motion.sequences) {
    const int partner = m.sequence % 2 == 1 ? m.sequence + 1 : m.sequence - 1;
    if (run_of_sequence.count(partner) == 0) {
      return bad_input(lines_of(log, m) + "has no pair: sequence " + std::to_string(partner) +
                       " is missing (sequences 2k-1 and 2k are opposite rotations of the same gimbal)");
    }
  }
  for (std::size_t p = 0; p + 1 < motion.sequences.size(); p += 2) {
    const SequenceMotion& a = motion.sequences[p];
    const SequenceMotion& b = motion.sequences[p + 1];
    const std::string where =
        lines_of(log, b) + "pairs with sequence " + std::to_string(a.sequence) + " but ";
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

  // The pair differences must excite three independent body axes.
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
        log.source + ": the " + std::to_string(pairs) + " sequence pairs excite only " +
        std::to_string(rank) +
        " independent body axes; the rotation plan needs rotations about three (e.g. seed Table 3)");
  }
  return motion;
}

}  // namespace tetra
