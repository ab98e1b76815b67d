// Attitude error, NEES, σ-fractions and integrated angles of `tetra score` (attitude_score.hpp).
#include "tetra/core/attitude_score.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "tetra/core/units.hpp"

namespace tetra {

namespace {

enum class Match { kExact, kInterpolated, kOutside };

struct TruthSample {
  Match match = Match::kOutside;
  Quaternion q_RB = Quaternion::Identity();
};

//! The truth attitude at `t_s`: a row within the tolerance, else slerp between the rows around it.
TruthSample truth_at(const AttitudeSeries& truth, double t_s, double tolerance_s) {
  const auto& times = truth.time_s;
  const auto it = std::lower_bound(times.begin(), times.end(), t_s - tolerance_s);
  const auto k = static_cast<std::size_t>(it - times.begin());
  if (k < times.size() && std::abs(times[k] - t_s) <= tolerance_s) return {Match::kExact, truth.q_RB[k]};
  if (k == 0 || k >= times.size()) return {};
  const double fraction = (t_s - times[k - 1]) / (times[k] - times[k - 1]);
  return {Match::kInterpolated, truth.q_RB[k - 1].slerp(fraction, truth.q_RB[k]).normalized()};
}

//! The row's 1σ: per axis when the file has them (NaN otherwise) and total.
void fill_sigma(const AttitudeSeries& attitude, std::size_t row, ScoredEpoch& e) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  e.sigma_B_deg = attitude.sigma_B_deg.empty() ? Eigen::Vector3d::Constant(nan) : attitude.sigma_B_deg[row];
  e.sigma_deg = attitude.sigma_deg.empty() ? nan : attitude.sigma_deg[row];
}

bool stated(double sigma) {
  return std::isfinite(sigma) && sigma > 0.0;
}

//! Sums over the scored epochs, turned into the score's statistics by finish().
struct Accumulator {
  Eigen::Vector3d sum_sq_B = Eigen::Vector3d::Zero();
  double sum_sq_total = 0.0;
  double sum_nees = 0.0;
  std::array<Eigen::Vector3d, 3> within_B{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                          Eigen::Vector3d::Zero()};
  std::array<double, 3> within_total{};

  void add(const ScoredEpoch& e, bool per_axis, AttitudeScore& score) {
    const double total = e.error_B_deg.norm();
    sum_sq_B += e.error_B_deg.cwiseAbs2();
    sum_sq_total += total * total;
    score.max_abs_B_deg = score.max_abs_B_deg.cwiseMax(e.error_B_deg.cwiseAbs());
    score.max_total_deg = std::max(score.max_total_deg, total);
    const bool has_sigma = per_axis ? stated(e.sigma_B_deg.minCoeff()) : stated(e.sigma_deg);
    if (!has_sigma) {
      ++score.no_sigma_epochs;
      return;
    }
    ++score.sigma_epochs;
    const double sigma_total = per_axis ? e.sigma_B_deg.norm() : e.sigma_deg;
    const Eigen::Vector3d z =
        per_axis ? Eigen::Vector3d(e.error_B_deg.cwiseQuotient(e.sigma_B_deg)) : Eigen::Vector3d::Zero();
    sum_nees += per_axis ? z.squaredNorm() : std::pow(total / sigma_total, 2);
    for (int k = 0; k < 3; ++k) {
      const double bound = static_cast<double>(k + 1);
      const auto uk = static_cast<std::size_t>(k);
      if (per_axis) within_B[uk] += (z.cwiseAbs().array() <= bound).cast<double>().matrix();
      within_total[uk] += total <= bound * sigma_total ? 1.0 : 0.0;
    }
  }

  void finish(AttitudeScore& score) const {
    const auto n = static_cast<double>(score.epochs.size());
    score.rms_B_deg = (sum_sq_B / n).cwiseSqrt();
    score.rms_total_deg = std::sqrt(sum_sq_total / n);
    score.final_total_deg = score.epochs.back().error_B_deg.norm();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto m = static_cast<double>(score.sigma_epochs);
    score.mean_nees = score.sigma_epochs > 0 ? sum_nees / m : nan;
    for (std::size_t k = 0; k < 3; ++k) {
      score.within_B[k] =
          score.per_axis_sigma && m > 0 ? Eigen::Vector3d(within_B[k] / m) : Eigen::Vector3d::Constant(nan);
      score.within_total[k] = m > 0 ? within_total[k] / m : nan;
    }
  }
};

}  // namespace

double integrated_angle_deg(const AttitudeSeries& series, const Eigen::Vector3d& axis_B) {
  double angle_deg = 0.0;
  for (std::size_t k = 1; k < series.time_s.size(); ++k) {
    angle_deg += axis_B.dot(series.rate_B_dps[k]) * (series.time_s[k] - series.time_s[k - 1]);
  }
  return angle_deg;
}

Result<AttitudeScore> score_attitude(const AttitudeSeries& attitude, const AttitudeSeries& truth,
                                     const ScoreOptions& options) {
  if (!(std::abs(options.axis_B.norm() - 1.0) <= 1e-9)) return bad_input({"axis_B"}, "not a unit vector");
  if (!(options.time_tolerance_s >= 0.0)) return bad_input({"time_tolerance_s"}, "must be ≥ 0");
  AttitudeScore score;
  score.per_axis_sigma = !attitude.sigma_B_deg.empty();
  score.nees_dof = score.per_axis_sigma ? 3 : 1;
  Accumulator acc;
  for (std::size_t r = 0; r < attitude.time_s.size(); ++r) {
    const TruthSample t = truth_at(truth, attitude.time_s[r], options.time_tolerance_s);
    if (t.match == Match::kOutside) {
      ++score.outside_truth;
      continue;
    }
    ++(t.match == Match::kExact ? score.exact_matches : score.interpolated);
    ScoredEpoch e;
    e.time_s = attitude.time_s[r];
    e.error_B_deg = quat_log(t.q_RB.conjugate() * attitude.q_RB[r]) * kRadToDeg;
    fill_sigma(attitude, r, e);
    score.epochs.push_back(e);
    acc.add(score.epochs.back(), score.per_axis_sigma, score);
  }
  if (score.epochs.empty()) {
    return bad_input(attitude.source + ": no row lies within the time span of " + truth.source);
  }
  acc.finish(score);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d u = Eigen::Vector3d::Unit(k);
    score.angle_B_deg(k) = integrated_angle_deg(attitude, u);
    score.truth_angle_B_deg(k) = integrated_angle_deg(truth, u);
  }
  score.angle_axis_deg = integrated_angle_deg(attitude, options.axis_B);
  score.truth_angle_axis_deg = integrated_angle_deg(truth, options.axis_B);
  return score;
}

}  // namespace tetra
