#include "own_noise_level.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference_noise_match.hpp"
#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

namespace {
constexpr double kMedianOfHalfNormal = 0.6744897501960817;  //!< median of |N(0,1)|
constexpr double kWhiteD4 = 70.0;                           //!< var(Δ⁴) of unit white noise: C(8,4)
constexpr double kQuantizationD4 = 252.0;  //!< var(Δ⁵e) of unit white angle error: C(10,5)
}  // namespace

OwnNoiseLevel::OwnNoiseLevel(const std::vector<GyroConstants>& constants, const PipelineConfig& config)
    : constants_(constants),
      window_(design::noise_window),
      high_ratio_(config.noise_high_ratio),
      tracks_(constants.size()),
      scratch_(static_cast<std::size_t>(design::noise_window), 0.0) {
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
  epochs_ = 0;
  std::fill(steps_ns_, steps_ns_ + 4, 0);
}

void OwnNoiseLevel::forget(int id) {
  clear(tracks_[static_cast<std::size_t>(id - 1)]);
}

void OwnNoiseLevel::bridge_gap() {
  for (auto& t : tracks_) t.consecutive = 0;
}

void OwnNoiseLevel::difference_weights(std::int64_t now_ns) {
  // The samples are the rate at their own instants (a jittered stamp is a jittered sample): the fourth
  // divided difference over the last five epochs' times, scaled by 4!·T̄⁴ (T̄ their mean spacing), is the
  // binomial Δ⁴ on an even grid and zero for any cubic in time on an uneven one, so a slew's acceleration
  // sampled at jittered instants leaves nothing (on the even weights it left α·jitter per sample, up to 20
  // times the white level of the families' agile slews at 5 ms). Normalized to the white noise's
  // Σa² = 70.
  for (int j = 4; j > 0; --j) times_ns_[j] = times_ns_[j - 1];
  times_ns_[0] = now_ns;
  epochs_ = std::min(epochs_ + 1, 5);
  if (epochs_ < 5) return;
  // The same spacings as the last epoch's (an even stream, nearly every epoch): the same weights.
  bool same = true;
  for (int j = 0; j < 4; ++j) {
    const std::int64_t step_ns = times_ns_[j] - times_ns_[j + 1];
    same = same && step_ns == steps_ns_[j];
    steps_ns_[j] = step_ns;
  }
  if (same) return;
  const double mean_step_s = ns_to_seconds(times_ns_[0] - times_ns_[4]) / 4.0;
  for (int j = 0; j < 4; ++j) {
    if (times_ns_[j] <= times_ns_[j + 1]) {  // not increasing (the pipeline's stamps are): the even grid's
      static constexpr double kEven[5] = {1.0, -4.0, 6.0, -4.0, 1.0};
      std::copy(kEven, kEven + 5, weights_);
      return;
    }
  }
  double sum_sq = 0.0;
  for (int j = 0; j < 5; ++j) {
    double product = 1.0;
    for (int m = 0; m < 5; ++m) {
      if (m != j) product *= ns_to_seconds(times_ns_[j] - times_ns_[m]) / mean_step_s;
    }
    weights_[j] = 24.0 / product;
    sum_sq += weights_[j] * weights_[j];
  }
  const double scale = std::sqrt(kWhiteD4 / sum_sq);
  for (double& w : weights_) w *= scale;
}

void OwnNoiseLevel::ingest(const EpochFrame& frame, double period_s) {
  if (period_s > 0.0 && std::abs(frame.dt_s - period_s) > 0.5 * period_s) bridge_gap();
  difference_weights(frame.now_ns);
  for (std::size_t u = 0; u < tracks_.size(); ++u) {
    Track& t = tracks_[u];
    if (!has_gyro(frame.valid, static_cast<int>(u) + 1)) {
      t.consecutive = 0;
      continue;
    }
    const double y = frame.y_rad_s[u];
    if (t.consecutive >= 4) {
      const double d4 = weights_[0] * y + weights_[1] * t.y[0] + weights_[2] * t.y[1] + weights_[3] * t.y[2] +
                        weights_[4] * t.y[3];
      t.d4[static_cast<std::size_t>(t.head)] = std::abs(d4);
      if (++t.head == window_) t.head = 0;  // the ring's next slot (no division at every epoch)
      t.count = std::min(t.count + 1, window_);
      t.since_eval = std::min(t.since_eval + 1, design::own_noise_eval_every);
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
  const double cap = design::reference_max_noise_ratio * design::reference_max_noise_ratio;
  return std::min(1.0 + (r * r - 1.0) * s * s / white, cap);
}

bool OwnNoiseLevel::evaluate(GyroMask candidates, double sqrt_period, std::vector<OwnNoiseFinding>& named) {
  named.clear();
  bool changed = false;
  for (int id = 1; id <= static_cast<int>(tracks_.size()); ++id) {
    Track& t = tracks_[static_cast<std::size_t>(id - 1)];
    if (!(t.named || has_gyro(candidates, id)) || t.since_eval < design::own_noise_eval_every) continue;
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
  t.smoothed += (lambda - t.smoothed) / design::own_noise_smoothing_evaluations;
  t.ratio = std::max(t.smoothed, lambda);
  return t.smoothed >= white_ratio(id, design::own_noise_normal_ratio, sqrt_period);
}

void OwnNoiseLevel::clear_name(Track& t) {
  t.named = false;
  t.ratio = 1.0;
  t.smoothed = 1.0;
}

}  // namespace tetra::fdi::detail
