#include "outlier_gate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

namespace {
constexpr int kCachedGyros = 8;  //!< up to this many gyros, the motion noise is kept per subset
}  // namespace

OutlierGate::OutlierGate(int n_gyros, const PipelineConfig& config)
    : config_(config),
      tracks_(static_cast<std::size_t>(n_gyros)),
      dy_(static_cast<std::size_t>(n_gyros), 0.0),
      p_(static_cast<std::size_t>(std::max(1, n_gyros - 3)), 0.0) {
  if (n_gyros <= kCachedGyros)
    motion_noise_.assign(std::size_t{1} << static_cast<unsigned>(n_gyros),
                         std::numeric_limits<double>::quiet_NaN());
}

void OutlierGate::restart() {
  for (auto& t : tracks_) {
    t.outlier_run = 0;
    t.has_last_good = false;
  }
  // The last step judged may have had the removed gyro in it: no call until a clean step of the gyros now in
  // use has shown the body within the bound.
  fast_motion_ = true;
  withdrawn_ = true;
}

void OutlierGate::reset() {
  for (auto& t : tracks_) t = Track{};
  fast_motion_ = false;
  left_out_ = 0;
  withdrawn_ = false;
}

void OutlierGate::update(EpochFrame& frame, SubsetCache& subsets, GyroSeries& series, Counters& counters,
                         Isolations& out) {
  const int culprit = jump_culprit(frame, subsets, series);
  left_out_ = culprit > 0 && has_gyro(frame.usable, culprit)
                  ? GyroMask{1} << static_cast<unsigned>(culprit - 1)
                  : GyroMask{0};
  withdrawn_ = false;
  if (culprit > 0) {
    auto& t = tracks_[static_cast<std::size_t>(culprit - 1)];
    const double raw = frame.raw[static_cast<std::size_t>(culprit - 1)];
    ++counters.samples_outlier;
    t.outlier_repeated = t.outlier_run == 0 || (t.outlier_repeated && raw == t.outlier_first_raw);
    if (t.outlier_run == 0) t.outlier_first_raw = raw;
    ++t.outlier_run;
  }
  for (int id = 1; id <= static_cast<int>(tracks_.size()); ++id) {
    if (!has_gyro(frame.usable, id)) continue;
    auto& t = tracks_[static_cast<std::size_t>(id - 1)];
    if (id == culprit) {  // left out of this epoch; a persistent outlier is an abrupt step
      frame.usable = without_gyro(frame.usable, id);
      if (t.outlier_run >= design::onset_confirm_epochs)
        out.push_back(classify_step(id, frame, series, subsets.sqrt_period()));
      continue;
    }
    if (t.outlier_run > 0) {  // the outlier went away: a spike
      t.outlier_run = 0;
      ++counters.spikes;
      series.record_spike(id, frame.now_ns);
    }
    t.has_last_good = true;
    t.last_good_y = frame.y_rad_s[static_cast<std::size_t>(id - 1)];
    t.last_good_ns = frame.now_ns;
  }
}

Isolation OutlierGate::classify_step(int id, const EpochFrame& frame, const GyroSeries& series,
                                     double sqrt_period) const {
  // At every epoch of the run only this gyro's hypothesis explained the step with a possible motion: the
  // rows are the run's length against the confirmation count (docs/fdi.md, "The sources").
  Isolation iso = step_kind(id, frame, series, sqrt_period);
  const auto& t = tracks_[static_cast<std::size_t>(id - 1)];
  iso.rows.own_signal(EvidenceSource::kJump, id, frame.usable, t.outlier_run, design::onset_confirm_epochs);
  return iso;
}

Isolation OutlierGate::step_kind(int id, const EpochFrame& frame, const GyroSeries& series,
                                 double sqrt_period) const {
  const auto& t = tracks_[static_cast<std::size_t>(id - 1)];
  const bool zero = t.outlier_repeated && frame.raw[static_cast<std::size_t>(id - 1)] == 0.0;
  const double r = series.recent_noise_ratio(id, sqrt_period, design::onset_confirm_epochs);
  if (t.outlier_repeated)
    return {id,
            FaultKind::kStuck,
            zero ? Evidence::kZero : Evidence::kRepeated,
            DetectionTest::kOnset,
            static_cast<double>(t.outlier_run),
            {}};
  if (std::isfinite(r) && r > config_.noise_high_ratio) {
    // A raised level while the body moves may be its jerk: the step is certain, its kind is not.
    const bool quiet = series.motion_quiet(id, sqrt_period, design::onset_confirm_epochs);
    return {id,
            quiet ? FaultKind::kNoise : FaultKind::kUnknown,
            quiet ? Evidence::kNoiseLevel : Evidence::kOnset,
            DetectionTest::kOnset,
            r,
            {}};
  }
  return {id, FaultKind::kBias, Evidence::kOnset, DetectionTest::kOnset, static_cast<double>(t.outlier_run),
          {}};
}

bool OutlierGate::possible_motion(const Subset& h, double dt_s, const GyroSeries& series,
                                  const SubsetCache& subsets) const {
  // The rate change the gyros of `h` imply since their last good samples, against a_max·Δt and its noise.
  const double a_max = config_.max_angular_acceleration_dps2 * kDegToRad;
  const Eigen::Vector3d dw = apply_pinv(h.pinv, h.mask, dy_.data());
  return dw.norm() <= a_max * dt_s + motion_noise(h, series, subsets.sqrt_period());
}

double OutlierGate::motion_noise(const Subset& h, const GyroSeries& series, double sqrt_period) const {
  const bool cached = h.mask < motion_noise_.size();
  if (cached && sqrt_period == motion_noise_period_ && !std::isnan(motion_noise_[h.mask]))
    return motion_noise_[h.mask];
  double var = 0.0;
  for (int i = 1; i <= static_cast<int>(tracks_.size()); ++i) {
    if (!has_gyro(h.mask, i)) continue;
    var += h.pinv.col(i - 1).squaredNorm() * series.difference_variance(i, sqrt_period);
  }
  const double noise = config_.onset_sigma * std::sqrt(var);
  if (cached) {
    if (sqrt_period != motion_noise_period_)
      std::fill(motion_noise_.begin(), motion_noise_.end(), std::numeric_limits<double>::quiet_NaN());
    motion_noise_period_ = sqrt_period;
    motion_noise_[h.mask] = noise;
  }
  return noise;
}

int OutlierGate::jump_culprit(const EpochFrame& frame, SubsetCache& subsets, const GyroSeries& series) {
  const GyroMask avail = frame.usable;
  const Subset& s = subsets.get(avail);
  spread_sample_ = std::numeric_limits<double>::quiet_NaN();
  consecutive_ = false;
  const std::int64_t previous_ns = previous_ns_;
  previous_ns_ = frame.now_ns;
  if (!s.observable || s.dof < 1) return 0;
  double dt_max = 0.0;
  std::int64_t since_ns = -1;
  bool consecutive = true;  // every gyro's last good sample is the previous epoch's
  for (int id = 1; id <= static_cast<int>(tracks_.size()); ++id) {
    if (!has_gyro(avail, id)) continue;
    const auto& t = tracks_[static_cast<std::size_t>(id - 1)];
    if (!t.has_last_good) return 0;
    consecutive = consecutive && t.outlier_run == 0 && t.last_good_ns == previous_ns;
    // Changes over different spans (a sample dropped since) differ by the body's own rate change over the
    // difference — during a slew, a jump of the gyro that missed one. No call; the next step is not judged
    // either until a step of equal spans has shown the body within the bound. (A gyro in an outlier run keeps
    // its last good sample from before the run on purpose: a step is judged against it.)
    if (t.outlier_run == 0) {
      if (since_ns >= 0 && t.last_good_ns != since_ns) {
        fast_motion_ = true;
        return 0;
      }
      since_ns = t.last_good_ns;
    }
    dt_max = std::max(dt_max, ns_to_seconds(frame.now_ns - t.last_good_ns));
    dy_[static_cast<std::size_t>(id - 1)] = frame.y_rad_s[static_cast<std::size_t>(id - 1)] - t.last_good_y;
  }
  // Δp = √T·W·Δy/√2 (a difference of two samples has twice the variance; W whitens the difference's noise).
  const double scale = subsets.sqrt_period() / std::sqrt(2.0);
  consecutive_ = consecutive;
  const double u = apply_whitened(s.jump_parity, s.dof, avail, dy_.data(), scale, p_.data());
  const bool possible = possible_motion(s, dt_max, series, subsets);
  // A difference of consecutive samples over a body within the bound on both steps: the parity's own spread.
  if (consecutive && !fast_motion_ && possible) {
    spread_sample_ = u;
    spread_dof_ = s.dof;
    spread_cap_ = s.jump_threshold;
  }
  if (u <= s.jump_threshold) {
    // No jump: this step's rate change is the body's own. Beyond the bound, the next step's cannot be judged.
    fast_motion_ = !possible;
    return 0;
  }
  // The body was turning faster than the bound allows on the last clean step: the true hypothesis may be the
  // impossible one, and a wrong one possible by a fault cancelling the motion. No call.
  if (fast_motion_) return 0;
  int consistent = 0;
  int culprit = 0;
  for (int j = 1; j <= static_cast<int>(tracks_.size()); ++j) {
    if (!has_gyro(avail, j)) continue;
    const Subset& h = subsets.get(without_gyro(avail, j));
    if (!h.observable) return 0;  // cannot judge: no outlier call
    bool ok = possible_motion(h, dt_max, series, subsets);
    if (ok && h.dof >= 1)
      ok = apply_whitened(h.jump_parity, h.dof, h.mask, dy_.data(), scale, p_.data()) <= h.jump_threshold;
    if (ok) {
      ++consistent;
      culprit = j;
    }
  }
  return consistent == 1 ? culprit : 0;
}

}  // namespace tetra::fdi::detail
