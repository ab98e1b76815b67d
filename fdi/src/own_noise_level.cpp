#include "own_noise_level.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference_noise_match.hpp"

namespace tetra::fdi::detail {

namespace {
constexpr int kOwnEvalEvery = 10;                           //!< [values] the level is evaluated this often
constexpr double kMedianOfHalfNormal = 0.6744897501960817;  //!< median of |N(0,1)|
constexpr double kWhiteD4 = 70.0;                           //!< var(Δ⁴) of unit white noise: C(8,4)
constexpr double kQuantizationD4 = 252.0;    //!< var(Δ⁵e) of unit white angle error: C(10,5)
constexpr double kSmoothEvaluations = 10.0;  //!< λ's smoothing, in evaluations
constexpr double kNormalLevel = 1.5;         //!< [-] a named gyro's smoothed level back below this: normal
}  // namespace

OwnNoiseLevel::OwnNoiseLevel(const std::vector<GyroConstants>& constants, const PipelineConfig& config)
    : constants_(constants),
      window_(config.noise_window),
      high_ratio_(config.noise_high_ratio),
      tracks_(constants.size()),
      scratch_(static_cast<std::size_t>(config.noise_window), 0.0) {
  for (auto& t : tracks_) t.d4.assign(static_cast<std::size_t>(window_), 0.0);
}

void OwnNoiseLevel::clear(Track& t) {
  t.consecutive = 0;
  t.count = 0;
  t.head = 0;
  t.since_eval = 0;
  clear_name(t);
}

void OwnNoiseLevel::reset() {
  for (auto& t : tracks_) clear(t);
}

void OwnNoiseLevel::forget(int id) {
  clear(tracks_[static_cast<std::size_t>(id - 1)]);
}

void OwnNoiseLevel::bridge_gap() {
  for (auto& t : tracks_) t.consecutive = 0;
}

void OwnNoiseLevel::ingest(const EpochFrame& frame, double period_s) {
  if (period_s > 0.0 && std::abs(frame.dt_s - period_s) > 0.5 * period_s) bridge_gap();
  for (std::size_t u = 0; u < tracks_.size(); ++u) {
    Track& t = tracks_[u];
    if (!has_gyro(frame.valid, static_cast<int>(u) + 1)) {
      t.consecutive = 0;
      continue;
    }
    const double y = frame.y_rad_s[u];
    if (t.consecutive >= 4) {
      const double d4 = y - 4.0 * t.y[0] + 6.0 * t.y[1] - 4.0 * t.y[2] + t.y[3];
      t.d4[static_cast<std::size_t>(t.head)] = std::abs(d4);
      t.head = (t.head + 1) % window_;
      t.count = std::min(t.count + 1, window_);
      t.since_eval = std::min(t.since_eval + 1, kOwnEvalEvery);
    }
    t.y[3] = t.y[2];
    t.y[2] = t.y[1];
    t.y[1] = t.y[0];
    t.y[0] = y;
    t.consecutive = std::min(t.consecutive + 1, 4);
  }
}

double OwnNoiseLevel::d4_sigma(int id, double sqrt_period) const {
  const GyroConstants& c = constants_[static_cast<std::size_t>(id - 1)];
  const double period = sqrt_period * sqrt_period;
  return std::sqrt(kWhiteD4 * c.arw_rad_rts * c.arw_rad_rts / period +
                   kQuantizationD4 * c.quantization_rad * c.quantization_rad / (period * period));
}

double OwnNoiseLevel::level(int id, double sqrt_period) const {
  const Track& t = tracks_[static_cast<std::size_t>(id - 1)];
  if (t.count < window_) return std::numeric_limits<double>::quiet_NaN();
  std::copy(t.d4.begin(), t.d4.end(), scratch_.begin());  // valid samples are finite (gyro_series)
  const double median = select_rank(scratch_.data(), window_, window_ / 2);
  return median / (kMedianOfHalfNormal * d4_sigma(id, sqrt_period));
}

double OwnNoiseLevel::white_ratio(int id, double r, double sqrt_period) const {
  const GyroConstants& c = constants_[static_cast<std::size_t>(id - 1)];
  const double s = d4_sigma(id, sqrt_period);
  const double white = kWhiteD4 * c.arw_rad_rts * c.arw_rad_rts / (sqrt_period * sqrt_period);
  if (!(white > 0.0) || !(r > 1.0)) return 1.0;
  const double cap = ReferenceNoiseMatch::kMaxNoiseRatio * ReferenceNoiseMatch::kMaxNoiseRatio;
  return std::min(1.0 + (r * r - 1.0) * s * s / white, cap);
}

bool OwnNoiseLevel::evaluate(GyroMask candidates, double sqrt_period, std::vector<OwnNoiseFinding>& named) {
  named.clear();
  bool changed = false;
  for (int id = 1; id <= static_cast<int>(tracks_.size()); ++id) {
    Track& t = tracks_[static_cast<std::size_t>(id - 1)];
    if (!(t.named || has_gyro(candidates, id)) || t.since_eval < kOwnEvalEvery) continue;
    t.since_eval = 0;
    const double r = level(id, sqrt_period);
    if (!std::isfinite(r)) continue;
    if (t.named) {
      if (!follow(t, id, r, sqrt_period)) clear_name(t);
      changed = true;
    } else if (r > high_ratio_) {
      t.named = true;
      t.smoothed = white_ratio(id, r, sqrt_period);
      t.ratio = t.smoothed;
      named.push_back({id, r, t.ratio});
      changed = true;
    }
  }
  return changed;
}

bool OwnNoiseLevel::follow(Track& t, int id, double r, double sqrt_period) const {
  const double lambda = white_ratio(id, r, sqrt_period);
  t.smoothed += (lambda - t.smoothed) / kSmoothEvaluations;
  t.ratio = std::max(t.smoothed, lambda);
  return t.smoothed >= white_ratio(id, kNormalLevel, sqrt_period);
}

void OwnNoiseLevel::clear_name(Track& t) {
  t.named = false;
  t.ratio = 1.0;
  t.smoothed = 1.0;
}

}  // namespace tetra::fdi::detail
