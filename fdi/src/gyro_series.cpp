#include "gyro_series.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

namespace {
constexpr double kNoiseExpectedMedian = 0.6744897501960817;  //!< median of |N(0,1)|
constexpr double kInf = std::numeric_limits<double>::infinity();
//! [-] relative margin of the counting decision on the noise ratio: far above the few ulps of rounding in
//! median/level, far below any meaningful change of the limits
constexpr double kRatioMargin = 1e-9;
}  // namespace

double select_rank(double* a, int n, int k) {
  int lo = 0;
  int hi = n - 1;
  while (hi > lo) {
    std::swap(a[lo + (hi - lo) / 2], a[hi]);  // the middle element as the pivot
    const double pivot = a[hi];
    int store = lo;  // a[lo, store) < pivot ≤ a[store, i)
    for (int i = lo; i < hi; ++i) {
      const double x = a[i];
      a[i] = a[store];
      a[store] = x;
      store += static_cast<int>(x < pivot);
    }
    std::swap(a[store], a[hi]);
    if (k == store) return a[k];
    if (k < store) {
      hi = store - 1;
    } else {
      lo = store + 1;
    }
  }
  return a[k];
}

bool rank_within(const double* a, int n, int k, double low, double high) {
  // The element of rank k exceeds `low` when at most k values are ≤ low, and is below `high` when more than k
  // values are < high.
  int at_most_low = 0;
  int under_high = 0;
  bool ordered = true;
  for (int i = 0; i < n; ++i) {
    at_most_low += static_cast<int>(a[i] <= low);
    under_high += static_cast<int>(a[i] < high);
    ordered &= !std::isnan(a[i]);
  }
  return ordered && at_most_low <= k && under_high > k;
}

Result<std::vector<GyroConstants>> gyro_constants(const Calibration& cal, const PipelineConfig& config) {
  std::vector<GyroConstants> out;
  for (std::size_t i = 0; i < cal.gyros.size(); ++i) {
    const auto& g = cal.gyros[i];
    GyroConstants c;
    const double n_dps =
        (g.noise && g.noise->arw_dps_rtHz) ? *g.noise->arw_dps_rtHz : config.default_arw_dps_rtHz;
    if (!(n_dps > 0.0) || !std::isfinite(n_dps)) {
      return bad_input("calibration: gyro " + std::to_string(i + 1) +
                       ": noise.arw_dps_rtHz must be positive");
    }
    c.arw_rad_rts = n_dps * kDegToRad;
    if (g.noise && g.noise->bias_instability_dps)
      c.bias_instability_rad_s = *g.noise->bias_instability_dps * kDegToRad;
    if (g.noise && g.noise->quantization_deg) c.quantization_rad = *g.noise->quantization_deg * kDegToRad;
    const double s = config.raw_units_dps ? 1.0 : g.scale_factor_V_per_dps;
    c.scale_V_per_rad_s = s / kDegToRad;
    c.bias_V = config.raw_units_dps ? 0.0 : g.bias_V;
    if (g.sigma && !config.raw_units_dps) {
      c.bias_sigma_rad_s = g.sigma->bias_V / std::abs(g.scale_factor_V_per_dps) * kDegToRad;
      c.scale_rel_sigma = g.sigma->scale_factor_V_per_dps / std::abs(g.scale_factor_V_per_dps);
    }
    if (g.sigma) c.axis_sigma = g.sigma->axis.cwiseAbs();
    out.push_back(c);
  }
  return out;
}

GyroSeries::GyroSeries(std::vector<GyroConstants> constants, const PipelineConfig& config)
    : constants_(std::move(constants)), config_(config), tracks_(constants_.size()) {
  for (auto& t : tracks_) {
    t.d2.assign(static_cast<std::size_t>(design::noise_window), 0.0);
    t.m2.assign(static_cast<std::size_t>(design::noise_window), kInf);
    t.view_coef.assign(tracks_.size(), 0.0);
    t.view_gyros.assign(tracks_.size(), 0);
  }
  scratch_.assign(static_cast<std::size_t>(std::max(design::noise_window, 8)), 0.0);
  d2_all_.assign(tracks_.size(), 0.0);
}

void GyroSeries::reset() {
  fresh_ = 0;
  for (auto& t : tracks_) {
    auto d2 = std::move(t.d2);
    auto m2 = std::move(t.m2);
    auto coef = std::move(t.view_coef);
    auto view_gyros = std::move(t.view_gyros);
    t = Track{};
    t.d2 = std::move(d2);
    t.m2 = std::move(m2);
    t.view_coef = std::move(coef);
    t.view_gyros = std::move(view_gyros);
  }
}

void GyroSeries::forget_evidence(int id) {
  auto& t = tracks_[static_cast<std::size_t>(id - 1)];
  t.spike_n = 0;
  t.repeat_count = 0;
  t.d2_count = 0;
  t.d2_since_eval = 0;
}

void GyroSeries::restart_evidence() {
  for (auto& t : tracks_) {
    std::fill(t.m2.begin(), t.m2.end(), kInf);  // unseen: the noise-level test makes no call on it
    t.run_seen = false;
    t.spike_n = 0;
  }
}

void GyroSeries::ingest(const Epoch& epoch, EpochFrame& frame, Counters& counters) {
  const double max_rate = config_.max_abs_rate_dps * kDegToRad;
  frame.valid = 0;
  fresh_ = 0;
  for (std::size_t u = 0; u < tracks_.size(); ++u) {
    auto& t = tracks_[u];
    t.d2_fresh = false;
    if (epoch.present[u] == 0) {
      ++counters.samples_absent;
      if (t.absent_since_ns < 0) t.absent_since_ns = frame.now_ns;
      t.consecutive = 0;
      continue;
    }
    t.absent_since_ns = -1;
    const double raw = epoch.raw[u];
    double y = kNaN;
    if (std::isfinite(raw) && std::abs(raw) <= config_.max_abs_raw_V)
      y = (raw - constants_[u].bias_V) / constants_[u].scale_V_per_rad_s;
    if (!std::isfinite(y) || std::abs(y) > max_rate) {
      ++counters.samples_invalid;
      if (t.invalid_since_ns < 0) t.invalid_since_ns = frame.now_ns;
      t.consecutive = 0;
      continue;
    }
    t.invalid_since_ns = -1;
    ++counters.samples_accepted;
    frame.valid |= GyroMask{1} << static_cast<unsigned>(u);
    frame.raw[u] = raw;
    frame.y_rad_s[u] = y;
    ingest_sample(t, raw, y);
    if (t.d2_fresh) {
      fresh_ |= GyroMask{1} << static_cast<unsigned>(u);
      d2_all_[u] = t.d2_last;
    }
  }
}

void GyroSeries::ingest_sample(Track& t, double raw, double y) {
  t.repeat_count = (t.has_last_raw && raw == t.last_raw) ? t.repeat_count + 1 : 1;
  if (t.repeat_count == 1) t.run_seen = false;
  t.has_last_raw = true;
  t.last_raw = raw;
  if (t.consecutive >= 2) {  // second difference Δ²y = y_k − 2y_{k−1} + y_{k−2}
    t.d2_last = y - 2.0 * t.y1 + t.y2;
    t.d2_fresh = true;
    t.d2[static_cast<std::size_t>(t.d2_head)] = std::abs(t.d2_last);
    t.m2[static_cast<std::size_t>(t.d2_head)] = kInf;  // until observe_motion sees the others' motion
    t.d2_head = (t.d2_head + 1) % design::noise_window;
    ++t.d2_count;
    ++t.d2_since_eval;
  }
  t.y2 = t.y1;
  t.y1 = y;
  t.consecutive = std::min(t.consecutive + 1, 2);
}

void GyroSeries::record_spike(int id, std::int64_t now_ns) {
  auto& t = tracks_[static_cast<std::size_t>(id - 1)];
  t.spike_ns[static_cast<std::size_t>(t.spike_n % kSpikeMemory)] = now_ns;
  ++t.spike_n;
}

void GyroSeries::observe_motion(const EpochFrame& frame, SubsetCache& subsets) {
  if (!subsets.ready()) return;
  const GyroMask fresh = fresh_ & frame.usable;
  for (int id = 1; id <= static_cast<int>(tracks_.size()); ++id) {
    if (!has_gyro(frame.valid, id)) continue;
    Track& t = tracks_[static_cast<std::size_t>(id - 1)];
    const GyroMask others = without_gyro(frame.usable, id);
    if (!motion_view(id, others, subsets)) continue;  // the others cannot see the motion: no evidence
    // A coarse gyro's repeat run: the rate the others see along its axis, cut into pieces.
    if (t.view_coarse) extend_run(id, t, project(t, frame.y_rad_s.data()), subsets.sqrt_period());
    // The motion's second difference along the axis, when every other gyro has one this epoch, in units of
    // the others' own noise on it.
    if (t.d2_fresh && (fresh & others) == others) {
      const int w = design::noise_window;
      t.motion_sigma = t.view_d2_sigma;
      t.m2[static_cast<std::size_t>((t.d2_head - 1 + w) % w)] =
          std::abs(project(t, d2_all_.data())) / t.motion_sigma;
    }
  }
}

double GyroSeries::run_width(int id, double sigma, double sqrt_period) const {
  const double step = std::sqrt(12.0) * constants(id).quantization_rad / (sqrt_period * sqrt_period);
  return 2.0 * step + 2.0 * config_.onset_sigma * sigma;
}

void GyroSeries::extend_run(int id, Track& t, double rate, double sqrt_period) {
  // Greedy, online: a piece grows while the range of its projections stays within the width a healthy
  // repeating gyro allows (its own rate stood within a step; two steps and the others' noise); a projection
  // beyond it starts the next piece. Greedy cuts the fewest pieces of any such split.
  if (!t.run_seen || t.view_rate_sigma > t.run_sigma) {
    // The run's first projection, or a noisier view (other gyros): pieces cut with the narrower width might
    // be one with this one. The count starts again from the current piece: fewer pieces, never more evidence.
    if (!t.run_seen) t.run_low = t.run_high = rate;
    t.run_sigma = t.view_rate_sigma;
    t.run_pieces = 1;
    t.run_seen = true;
  }
  const double low = std::min(t.run_low, rate);
  const double high = std::max(t.run_high, rate);
  if (high - low <= run_width(id, t.run_sigma, sqrt_period)) {
    t.run_low = low;
    t.run_high = high;
    return;
  }
  ++t.run_pieces;
  t.run_low = t.run_high = rate;
}

bool GyroSeries::motion_view(int id, GyroMask others, SubsetCache& subsets) {
  const Track& t = track(id);
  if (t.view_mask == others && t.view_period == subsets.sqrt_period()) return t.view_observable;
  return make_view(id, others, subsets);
}

bool GyroSeries::make_view(int id, GyroMask others, SubsetCache& subsets) {
  // The coefficients of h_i·H*_(others) and the noise they carry, once per set of others.
  Track& t = tracks_[static_cast<std::size_t>(id - 1)];
  t.view_mask = others;
  t.view_period = subsets.sqrt_period();
  t.view_coarse = coarse(id, t.view_period);
  t.view_count = 0;
  const Subset& h = subsets.get(others);
  t.view_observable = h.observable;
  if (!h.observable) return false;
  const Eigen::RowVector3d axis = subsets.geometry().axes_B().row(id - 1);
  double var = 0.0;
  double var_d2 = 0.0;
  for (int k = 1; k <= static_cast<int>(tracks_.size()); ++k) {
    const double c = has_gyro(others, k) ? static_cast<double>(axis * h.pinv.col(k - 1)) : 0.0;
    t.view_coef[static_cast<std::size_t>(k - 1)] = c;
    if (has_gyro(others, k)) t.view_gyros[static_cast<std::size_t>(t.view_count++)] = k - 1;
    var += c * c * sample_sigma(k, t.view_period) * sample_sigma(k, t.view_period);
    var_d2 += c * c * d2_sigma(k, t.view_period) * d2_sigma(k, t.view_period);
  }
  t.view_rate_sigma = std::sqrt(var);
  t.view_d2_sigma = std::sqrt(var_d2);
  return true;
}

double GyroSeries::project(const Track& t, const double* v) const {
  double sum = 0.0;
  for (int j = 0; j < t.view_count; ++j) {
    const auto k = static_cast<std::size_t>(t.view_gyros[static_cast<std::size_t>(j)]);
    sum += t.view_coef[k] * v[k];
  }
  return sum;
}

double GyroSeries::sample_sigma(int id, double sqrt_period) const {
  const GyroConstants& c = constants(id);
  return std::sqrt(sample_variance(c.arw_rad_rts, c.quantization_rad, sqrt_period * sqrt_period));
}

double GyroSeries::window_mean_variance(int id, double sqrt_period, int n) const {
  const GyroConstants& c = constants(id);
  return mean_variance(c.arw_rad_rts, c.quantization_rad, sqrt_period * sqrt_period, n);
}

double GyroSeries::difference_variance(int id, double sqrt_period) const {
  const GyroConstants& c = constants(id);
  return sample_difference_variance(c.arw_rad_rts, c.quantization_rad, sqrt_period * sqrt_period);
}

bool GyroSeries::coarse(int id, double sqrt_period) const {
  const GyroConstants& c = constants(id);
  const double step = std::sqrt(12.0) * c.quantization_rad / (sqrt_period * sqrt_period);
  return step > design::coarse_step_per_sigma * c.arw_rad_rts / sqrt_period;
}

double GyroSeries::d2_sigma(int id, double sqrt_period) const {
  // Δ²y of white noise has variance 6σ²; of the quantization error (e_k − e_{k−1})/T with var(e) = Q²,
  // 20Q²/T².
  const GyroConstants& c = constants(id);
  const double period = sqrt_period * sqrt_period;
  return std::sqrt(6.0 * c.arw_rad_rts * c.arw_rad_rts / period +
                   20.0 * c.quantization_rad * c.quantization_rad / (period * period));
}

bool GyroSeries::motion_quiet(int id, double sqrt_period, int last) const {
  // The whole window: its median, as the noise-level test. The last samples: their trimmed RMS, as the kind
  // at isolation (a slew beginning within them must count, however few samples it has reached).
  const Track& t = track(id);
  const int n = std::min({last, t.d2_count, design::noise_window});
  const double motion =
      last == 0 ? noise_ratio(id, sqrt_period, 0, true) : (n < 6 ? kNaN : trimmed_rms(t.m2, t, n));
  return std::isfinite(motion) && motion <= design::quiet_motion_sigmas;
}

bool GyroSeries::noise_beyond_motion(int id, const Track& t, double r, double sqrt_period) const {
  // With four gyros a slew's jerk and one gyro's noise leave the same single residual: the gyro's own level
  // tells them apart only while the motion is quiet. The motion the other gyros see along this axis (in units
  // of their own noise on it, ≈ 1 at rest; ∞ when they could not see it) must be within
  // design::quiet_motion_sigmas, and the gyro's level beyond the limit by more than that motion could hide:
  // its level in the gyro's own σ units (the others' noise on it is large where their geometry is poor).
  // Another gyro's raised level means motion or a second fault: neither leaves this gyro alone to blame.
  if (!motion_quiet(id, sqrt_period, 0) || !others_normal(id, sqrt_period)) return false;
  const double motion = noise_ratio(id, sqrt_period, 0, true);
  return r > config_.noise_high_ratio + motion * t.motion_sigma / d2_sigma(id, sqrt_period);
}

double GyroSeries::unit_level(double sqrt_period) const {
  // The median of the gyros' levels in use (the upper one of an even count's two), at least 1.
  constexpr int kMaxUnitGyros = 32;  // a GyroMask's bits
  double levels[kMaxUnitGyros];
  int n = 0;
  for (int j = 1; j <= static_cast<int>(tracks_.size()) && n < kMaxUnitGyros; ++j) {
    if (has_gyro(excluded_, j)) continue;
    const double r = noise_ratio(j, sqrt_period);
    if (std::isfinite(r)) levels[n++] = r;
  }
  if (n < 3) return 1.0;
  std::nth_element(levels, levels + n / 2, levels + n);
  return std::max(1.0, levels[n / 2]);
}

bool GyroSeries::others_normal(int id, double sqrt_period) const {
  for (int j = 1; j <= static_cast<int>(tracks_.size()); ++j) {
    if (j == id || has_gyro(excluded_, j)) continue;
    const double r = noise_ratio(j, sqrt_period);
    if (!std::isfinite(r) || r > design::motion_quiet_ratio) return false;
    // A finely quantized output repeating its value has just stuck (its own test needs more repeats): its
    // frozen output is part of the motion the others see along this axis, which then hides the jerk of a
    // slew's start from it (N = 4, a gyro at 0 V as a slew began: the healthy one was excluded first).
    if (!coarse(j, sqrt_period) && track(j).repeat_count >= design::other_repeats_samples) return false;
  }
  return true;
}

bool GyroSeries::repeats_are_stuck(int id, const Track& t, double sqrt_period) const {
  if (!coarse(id, sqrt_period)) return true;  // identical values of a finely quantized output: stuck
  // Another gyro repeating too (design::other_repeats_samples values: it may have just stuck) may be the
  // stuck one, and its output is part of the motion the others see.
  for (int j = 1; j <= static_cast<int>(tracks_.size()); ++j) {
    if (j != id && !has_gyro(excluded_, j) && track(j).repeat_count >= design::other_repeats_samples)
      return false;
  }
  // A healthy quantized gyro's sample is the mean rate over the sample period within one step: when the rate
  // the others see along its axis moved by two steps beyond their noise, its output must have changed — if
  // the others are healthy. A fault of one of them moves that view too (a bias step of 0.017 deg/s on gyro 1
  // moves gyro 2's by 0.019 deg/s, one width), so its repeats are stuck only when no fault of one other gyro
  // that changed at most twice during the run explains the view: more pieces than such a fault leaves.
  return t.run_seen && t.run_pieces > design::pieces_one_fault_explains;
}

double* GyroSeries::recent(const std::vector<double>& ring, const Track& t, int n) const {
  const int w = design::noise_window;
  double* buf = scratch_.data();
  for (int k = 0; k < n; ++k) buf[k] = ring[static_cast<std::size_t>((t.d2_head - 1 - k + 2 * w) % w)];
  return buf;
}

double GyroSeries::noise_ratio(int id, double sqrt_period, int last, bool motion) const {
  const Track& t = track(id);
  const std::vector<double>& ring = motion ? t.m2 : t.d2;
  const int w = design::noise_window;
  const int n = last > 0 ? std::min({last, t.d2_count, w}) : std::min(t.d2_count, w);
  if (n < (last > 0 ? std::min(10, w) : w)) return kNaN;
  double* buf = scratch_.data();
  if (n == w) {
    std::copy(ring.begin(), ring.end(), buf);  // the whole ring: order does not matter for a median
  } else {
    buf = recent(ring, t, n);
  }
  bool ordered = true;
  for (int k = 0; k < n; ++k) ordered &= !std::isnan(buf[k]);
  double median = 0.0;
  if (ordered) {
    median = select_rank(buf, n, n / 2);
  } else {
    std::nth_element(buf, buf + n / 2, buf + n);
    median = buf[n / 2];
  }
  // Gaussian Δ²y of level σ_Δ²: median |Δ²y| = 0.6745·σ_Δ² (the motion's ring is already in its σ units).
  return median / (kNoiseExpectedMedian * (motion ? 1.0 : d2_sigma(id, sqrt_period)));
}

bool GyroSeries::noise_ratio_within(const Track& t, int id, double sqrt_period, double low,
                                    double high) const {
  // The limits on the ratio as limits on the median, moved inward by kRatioMargin (relative) so that the
  // rounding of median/level cannot put the ratio itself across a limit that the median is inside of.
  const int w = design::noise_window;
  if (t.d2_count < w) return false;
  const double level = kNoiseExpectedMedian * d2_sigma(id, sqrt_period);
  return rank_within(t.d2.data(), w, w / 2, low * level * (1.0 + kRatioMargin),
                     high * level * (1.0 - kRatioMargin));
}

double GyroSeries::recent_noise_ratio(int id, double sqrt_period, int last) const {
  // RMS of the last `last` second differences without their two largest (a step leaves exactly two), over
  // the expected √6·σ. Efficient on few samples, where the median is not.
  const Track& t = track(id);
  const int n = std::min({last, t.d2_count, design::noise_window});
  if (n < 6) return kNaN;
  return trimmed_rms(t.d2, t, n) / d2_sigma(id, sqrt_period);
}

double GyroSeries::trimmed_rms(const std::vector<double>& ring, const Track& t, int n) const {
  double* buf = recent(ring, t, n);
  std::sort(buf, buf + n);
  double sum_sq = 0.0;
  for (int k = 0; k < n - 2; ++k) sum_sq += buf[k] * buf[k];
  return std::sqrt(sum_sq / (n - 2));
}

void GyroSeries::check(std::int64_t now_ns, GyroMask excluded, double period_s, double sqrt_period,
                       Isolations& out) {
  excluded_ = excluded;
  const int n = static_cast<int>(tracks_.size());
  for (int id = 1; id <= n; ++id) {
    Track& t = tracks_[static_cast<std::size_t>(id - 1)];
    if (!has_gyro(excluded, id) && may_signal(t)) (void)check_one(id, t, now_ns, period_s, sqrt_period, out);
  }
}

bool GyroSeries::may_signal(const Track& t) const {
  // The entry condition of each signature of check_one: most epochs meet none of them.
  return t.absent_since_ns >= 0 || t.invalid_since_ns >= 0 || t.repeat_count >= design::stuck_repeat_count ||
         t.d2_since_eval >= design::noise_eval_every_samples || t.spike_n >= design::spike_count;
}

bool GyroSeries::check_one(int id, Track& t, std::int64_t now_ns, double period_s, double sqrt_period,
                           Isolations& out) {
  // A signature is the gyro's own signal: the hypothesis that it is healthy (every other gyro's, H0, Href)
  // is rejected by the statistic that names it (docs/fdi.md, "The sources").
  const GyroMask active = all_gyros(static_cast<int>(tracks_.size())) & ~excluded_;
  auto found = [&](FaultKind kind, Evidence evidence, double statistic, double threshold) {
    Isolation iso{id, kind, evidence, DetectionTest::kSignature, statistic, {}};
    iso.rows.own_signal(source_of(evidence), id, active, statistic, threshold);
    out.push_back(iso);
    return true;
  };
  if (t.absent_since_ns >= 0 && now_ns - t.absent_since_ns >= seconds_to_ns(config_.dropout_timeout_s))
    return found(FaultKind::kDropout, Evidence::kTimeout, ns_to_seconds(now_ns - t.absent_since_ns),
                 config_.dropout_timeout_s);
  if (t.invalid_since_ns >= 0 && now_ns - t.invalid_since_ns >= seconds_to_ns(config_.dropout_timeout_s))
    return found(FaultKind::kInvalid, Evidence::kInvalid, ns_to_seconds(now_ns - t.invalid_since_ns),
                 config_.dropout_timeout_s);
  if (t.repeat_count >= design::stuck_repeat_count && repeats_are_stuck(id, t, sqrt_period))
    return found(FaultKind::kStuck, t.last_raw == 0.0 ? Evidence::kZero : Evidence::kRepeated, t.repeat_count,
                 design::stuck_repeat_count);
  if (t.d2_since_eval >= design::noise_eval_every_samples && period_s > 0.0) {
    t.d2_since_eval = 0;
    if (!noise_ratio_within(t, id, sqrt_period, design::noise_low_ratio, config_.noise_high_ratio)) {
      // A raised level is judged against the unit's own (the gyros' median): a unit noisier than stated is
      // not one noisy gyro (docs/fdi.md, "A unit noisier than its noise: section"); a low one against the
      // stated noise.
      const double level = noise_ratio(id, sqrt_period);
      const double r = level / unit_level(sqrt_period);
      if (std::isfinite(r) && r > config_.noise_high_ratio && noise_beyond_motion(id, t, r, sqrt_period))
        return found(FaultKind::kNoise, Evidence::kNoiseLevel, r, config_.noise_high_ratio);
      if (std::isfinite(level) && level < design::noise_low_ratio && !coarse(id, sqrt_period))
        return found(FaultKind::kStuck, Evidence::kVariance, level, design::noise_low_ratio);
    }
  }
  // Recurring spikes: enough confirmed one-epoch outliers within the window, the first one old enough for the
  // noise-level test to have spoken, and the gyro's noise level otherwise normal.
  if (t.spike_n < design::spike_count) return false;
  const std::int64_t t_first =
      t.spike_ns[static_cast<std::size_t>((t.spike_n - design::spike_count) % kSpikeMemory)];
  const std::int64_t age = now_ns - t_first;
  if (age > seconds_to_ns(design::spike_window_s) ||
      age <
          seconds_to_ns(3.0 * design::noise_eval_every_samples * period_s + design::noise_window * period_s))
    return false;
  const double r = noise_ratio(id, sqrt_period);
  if (std::isfinite(r) && r < design::noise_raised_fraction * config_.noise_high_ratio)
    return found(FaultKind::kSpike, Evidence::kRecurringSpikes, design::spike_count, design::spike_count);
  return false;
}

}  // namespace tetra::fdi::detail
