// Overlapping Allan variance, averaging times, sampling grid and the whole-log analysis.
// The noise fit is in allan_fit.cpp, the reports in allan_report.cpp.
#include "tetra/core/allan.hpp"

#include "allan_internal.hpp"
#include "tetra/core/units.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <optional>
#include <thread>

namespace tetra::allan {

namespace {

// Work limit of --taus all: samples × averaging times (≈ 1 ns each).
constexpr double kAllTauWorkLimit = 4e9;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string format_number(double v) {
  char buf[32];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 6);
  return std::string(buf, ptr);
}

void add_unique(std::vector<std::int64_t>& ms, std::int64_t m, std::int64_t m_max) {
  if (m >= 1 && m <= m_max) ms.push_back(m);
}

}  // namespace

Result<TauSpec> parse_tau_spec(std::string_view text) {
  text = trim(text);
  TauSpec spec;
  if (text.empty() || text == "default") return spec;
  if (text == "octave") {
    spec.spacing = TauSpacing::kOctave;
    return spec;
  }
  if (text == "decade") {
    spec.spacing = TauSpacing::kDecade;
    return spec;
  }
  if (text == "all") {
    spec.spacing = TauSpacing::kAll;
    return spec;
  }
  spec.spacing = TauSpacing::kList;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string_view item =
        trim(text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    double tau = 0.0;
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), tau);
    if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || !std::isfinite(tau)) {
      return bad_input(
          {kSubjectTaus},
          "'" + std::string(item) +
              "' is not an averaging time in seconds (expected octave, decade, all or a list like "
              "0.1,1,10)");
    }
    if (tau <= 0.0) {
      return bad_input({kSubjectTaus}, "averaging time " + std::string(item) + " s is not positive");
    }
    spec.list_s.push_back(tau);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return spec;
}

Result<std::vector<std::int64_t>> averaging_factors(const TauSpec& spec, std::size_t samples, double tau0_s) {
  const auto m_max = static_cast<std::int64_t>(samples / 2);
  if (m_max < 1)
    return bad_input("need at least 2 samples for an Allan variance, have " + std::to_string(samples));
  std::vector<std::int64_t> ms;
  switch (spec.spacing) {
    case TauSpacing::kDefault:
      for (int j = 0;; ++j) {
        const double m = std::round(std::pow(10.0, j / 10.0));
        if (m > static_cast<double>(m_max)) break;
        add_unique(ms, static_cast<std::int64_t>(m), m_max);
      }
      break;
    case TauSpacing::kOctave:
      for (std::int64_t m = 1; m <= m_max; m *= 2) ms.push_back(m);
      break;
    case TauSpacing::kDecade:
      for (std::int64_t decade = 1; decade <= m_max; decade *= 10) {
        for (const std::int64_t k : {1, 2, 5}) add_unique(ms, k * decade, m_max);
      }
      break;
    case TauSpacing::kAll: {
      const double work = static_cast<double>(samples) * static_cast<double>(m_max);
      if (work > kAllTauWorkLimit) {
        return bad_input({kSubjectTaus},
                         "'all' on " + std::to_string(samples) + " samples means " + std::to_string(m_max) +
                             " averaging times of O(n) each, too slow; use the default, octave, decade or a "
                             "list");
      }
      for (std::int64_t m = 1; m <= m_max; ++m) ms.push_back(m);
      break;
    }
    case TauSpacing::kList:
      for (const double tau : spec.list_s) {
        if (!(tau > 0.0))
          return bad_input({kSubjectTaus}, "averaging time " + format_number(tau) + " s is not positive");
        const double m = std::round(tau / tau0_s);
        if (m < 1.0) {
          return bad_input({kSubjectTaus}, "averaging time " + format_number(tau) +
                                               " s is shorter than the sampling interval " +
                                               format_number(tau0_s) + " s");
        }
        if (m > static_cast<double>(m_max)) {
          return bad_input({kSubjectTaus}, "averaging time " + format_number(tau) +
                                               " s exceeds half the record (" +
                                               format_number(static_cast<double>(m_max) * tau0_s) +
                                               " s): no Allan variance there");
        }
        ms.push_back(static_cast<std::int64_t>(m));
      }
      break;
  }
  std::sort(ms.begin(), ms.end());
  ms.erase(std::unique(ms.begin(), ms.end()), ms.end());
  return ms;
}

Result<SamplingGrid> uniform_grid(std::span<const double> time_s, double tolerance, const std::string& source,
                                  std::span<const std::size_t> lines) {
  return uniform_grid_lines(time_s, tolerance, source, [&](std::size_t row) -> std::optional<std::size_t> {
    if (row < lines.size()) return lines[row];
    return std::nullopt;
  });
}

Result<SamplingGrid> uniform_grid_lines(
    std::span<const double> time_s, double tolerance, const std::string& source,
    const std::function<std::optional<std::size_t>(std::size_t)>& line_of) {
  const std::size_t n = time_s.size();
  auto where = [&](std::size_t row) {
    const auto line = line_of(row);
    return source + ":" + (line ? std::to_string(*line) : "row " + std::to_string(row + 1)) + ": ";
  };
  if (n < 2) {
    return bad_input(source + ": " + std::to_string(n) + " sample" + (n == 1 ? "" : "s") +
                     ": an Allan variance needs at least 2");
  }
  // One temporary (the steps, reordered for the median); the steps are recomputed afterwards.
  auto step = [&](std::size_t r) { return time_s[r + 1] - time_s[r]; };
  SamplingGrid grid;
  {
    std::vector<double> sorted(n - 1);
    for (std::size_t r = 0; r + 1 < n; ++r) {
      sorted[r] = step(r);
      if (!(sorted[r] > 0.0)) {
        return bad_input(where(r + 1) + "column 'time_s': time " + format_number(time_s[r + 1]) +
                         " s does not increase (previous " + format_number(time_s[r]) + " s)");
      }
    }
    const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    grid.tau0_s = *mid;
  }
  grid.slot.resize(n);
  std::size_t slot = 0;
  for (std::size_t r = 0; r < n; ++r) {
    if (r > 0) {
      const double dt = step(r - 1);
      const double k = std::round(dt / grid.tau0_s);
      if (k < 1.0 || std::abs(dt - k * grid.tau0_s) > tolerance * grid.tau0_s) {
        return bad_input(where(r) + "column 'time_s': time step " + format_number(dt) +
                         " s is not a whole multiple of the sampling interval " + format_number(grid.tau0_s) +
                         " s (median) within " + format_number(100.0 * tolerance) +
                         " %: non-uniform sampling");
      }
      if (k > static_cast<double>(4 * n)) {
        return bad_input(where(r) + "column 'time_s': time jumps by " + format_number(dt) +
                         " s, more than the whole record at the sampling interval " +
                         format_number(grid.tau0_s) + " s");
      }
      slot += static_cast<std::size_t>(k);
    }
    grid.slot[r] = slot;
  }
  grid.slots = slot + 1;
  grid.missing_epochs = grid.slots - n;
  // The mean step over the whole grid is a better τ0 than the median of rounded time stamps.
  grid.tau0_s = (time_s[n - 1] - time_s[0]) / static_cast<double>(slot);
  if (grid.missing_epochs > 4 * n) {
    return bad_input(source + ": missing epochs (" + std::to_string(grid.missing_epochs) +
                     ") outnumber the rows four to one: is time_s in seconds?");
  }
  return grid;
}

std::vector<AvarPoint> overlapping_avar(std::span<const double> rate, std::span<const std::uint8_t> present,
                                        double tau0_s, std::span<const std::int64_t> m_values,
                                        Interrupt* interrupt) {
  const std::size_t n = rate.size();
  auto is_present = [&](std::size_t i) {
    return (present.empty() || present[i] != 0) && std::isfinite(rate[i]);
  };
  // Remove the mean before summing: the Allan variance ignores a constant, and a large offset (raw
  // volts) would otherwise cost digits in the second differences of the cumulative sum.
  long double mean_acc = 0.0L;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (is_present(i)) {
      mean_acc += rate[i];
      ++count;
    }
  }
  const double mean = count > 0 ? static_cast<double>(mean_acc / static_cast<long double>(count)) : 0.0;

  // Angle x (in units of τ0, scaled out below) and cumulative count of present samples.
  std::vector<double> x(n + 1);
  std::vector<std::uint32_t> cum(n + 1);
  long double acc = 0.0L;
  std::uint32_t c = 0;
  x[0] = 0.0;
  cum[0] = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (is_present(i)) {
      acc += static_cast<long double>(rate[i] - mean);
      ++c;
    }
    x[i + 1] = static_cast<double>(acc);
    cum[i + 1] = c;
  }
  return avar_from_angle(x.data(), count == n ? nullptr : cum.data(), n, tau0_s, m_values, interrupt);
}

std::vector<AvarPoint> avar_from_angle(const double* x, const std::uint32_t* cum, std::size_t n,
                                       double tau0_s, std::span<const std::int64_t> m_values,
                                       Interrupt* interrupt) {
  const bool complete = cum == nullptr;
  std::vector<AvarPoint> out;
  out.reserve(m_values.size());
  for (const std::int64_t m_signed : m_values) {
    if (interrupt_requested(interrupt, out.size(), m_values.size())) break;
    AvarPoint p;
    p.m = m_signed;
    p.tau_s = static_cast<double>(m_signed) * tau0_s;
    p.avar = kNaN;
    if (m_signed < 1 || static_cast<std::size_t>(2 * m_signed) > n) {
      out.push_back(p);
      continue;
    }
    const auto m = static_cast<std::size_t>(m_signed);
    const std::size_t last = n - 2 * m;  // i = 0..last
    double sum = 0.0;
    std::int64_t terms = 0;
    if (complete) {
      // Four partial sums: independent chains the CPU can overlap (the order is fixed, so results
      // are reproducible).
      double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
      const double* xa = x;
      const double* xb = x + m;
      const double* xc = x + 2 * m;
      std::size_t i = 0;
      for (; i + 3 <= last; i += 4) {
        const double d0 = xc[i] - 2.0 * xb[i] + xa[i];
        const double d1 = xc[i + 1] - 2.0 * xb[i + 1] + xa[i + 1];
        const double d2 = xc[i + 2] - 2.0 * xb[i + 2] + xa[i + 2];
        const double d3 = xc[i + 3] - 2.0 * xb[i + 3] + xa[i + 3];
        s0 += d0 * d0;
        s1 += d1 * d1;
        s2 += d2 * d2;
        s3 += d3 * d3;
      }
      for (; i <= last; ++i) {
        const double d = xc[i] - 2.0 * xb[i] + xa[i];
        s0 += d * d;
      }
      sum = (s0 + s1) + (s2 + s3);
      terms = static_cast<std::int64_t>(last + 1);
    } else {
      const auto window = static_cast<std::uint32_t>(2 * m);
      for (std::size_t i = 0; i <= last; ++i) {
        if (cum[i + 2 * m] - cum[i] != window) continue;
        const double d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
        sum += d * d;
        ++terms;
      }
    }
    p.terms = terms;
    if (terms > 0) {
      // x is in units of τ0 (rate sums); the angle difference divided by τ is d·τ0/(m·τ0) = d/m.
      const double md = static_cast<double>(m);
      p.avar = sum / (2.0 * md * md * static_cast<double>(terms));
    }
    out.push_back(p);
  }
  return out;
}

namespace {

// Lengths of the maximal runs of consecutive valid samples.
std::vector<std::size_t> valid_runs(std::span<const double> rate, std::span<const std::uint8_t> present) {
  std::vector<std::size_t> runs;
  std::size_t run = 0;
  for (std::size_t i = 0; i < rate.size(); ++i) {
    if ((present.empty() || present[i] != 0) && std::isfinite(rate[i])) {
      ++run;
    } else if (run > 0) {
      runs.push_back(run);
      run = 0;
    }
  }
  if (run > 0) runs.push_back(run);
  return runs;
}

// EDF and confidence interval of each point for the noise types chosen per point. With gaps, each
// run of consecutive samples is an independent record: the EDF is the sum over the runs long
// enough for the averaging time (a run of L samples has L + 1 angle points).
// `interrupt` (optional) is polled every 16 points (a chi-square quantile of a large EDF takes up to a
// millisecond); once it asks to stop, the points are left as they are.
void set_intervals(std::vector<AdevPoint>& points, const std::vector<AvarPoint>& avar,
                   const std::vector<std::size_t>& runs, double confidence, bool with_bounds,
                   Interrupt* interrupt) {
  const double p_hi = 0.5 * (1.0 + confidence);
  const double p_lo = 0.5 * (1.0 - confidence);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i % 16 == 0 && interrupt_requested(interrupt, points.size(), points.size())) return;
    AdevPoint& pt = points[i];
    const double m = static_cast<double>(avar[i].m);
    double edf = 0.0;
    for (const std::size_t run : runs) {
      if (run >= static_cast<std::size_t>(2 * avar[i].m)) {
        edf += overlapping_avar_edf(pt.noise, static_cast<double>(run + 1), m);
      }
    }
    pt.edf = std::max(1.0, edf);
    const double v = avar[i].avar;
    pt.adev = std::sqrt(v);
    if (!with_bounds) continue;  // passes before the last only need the EDF for the fit weights
    pt.adev_lo = std::sqrt(v * pt.edf / chi2_quantile(p_hi, pt.edf));
    pt.adev_hi = std::sqrt(v * pt.edf / chi2_quantile(p_lo, pt.edf));
  }
}

// Noise type of each point from the fitted model: that of its largest term.
bool classify(std::vector<AdevPoint>& points, const NoiseFit& fit) {
  bool changed = false;
  for (AdevPoint& pt : points) {
    int best = -1;
    double best_value = 0.0;
    for (int k = 0; k < kTermCount; ++k) {
      const double c = fit.value[static_cast<std::size_t>(k)];
      const double contribution = c * c * term_basis(k, pt.tau_s);
      if (contribution > best_value) {
        best_value = contribution;
        best = k;
      }
    }
    const NoiseType type = best < 0 ? NoiseType::kWhiteRate : term_noise_type(best);
    changed = changed || type != pt.noise;
    pt.noise = type;
  }
  return changed;
}

}  // namespace

Status check_series_options(double tau0_s, const AllanOptions& options) {
  if (!(options.confidence > 0.0 && options.confidence < 1.0)) {
    return bad_input("confidence level " + format_number(options.confidence) + " is not between 0 and 1");
  }
  if (!(tau0_s > 0.0) || !std::isfinite(tau0_s)) {
    return bad_input("sampling interval " + format_number(tau0_s) + " s is not positive");
  }
  return ok_status();
}

Status check_present_samples(std::size_t present_samples) {
  if (present_samples < 2) {
    return bad_input(std::to_string(present_samples) +
                     " valid sample(s): an Allan variance needs at least 2");
  }
  return ok_status();
}

Result<AllanResult> analyze_series(std::span<const double> rate, std::span<const std::uint8_t> present,
                                   double tau0_s, const AllanOptions& options) {
  if (Status st = check_series_options(tau0_s, options); !st) return st.error();
  std::size_t present_samples = 0;
  for (std::size_t i = 0; i < rate.size(); ++i) {
    if ((present.empty() || present[i] != 0) && std::isfinite(rate[i])) ++present_samples;
  }
  if (Status st = check_present_samples(present_samples); !st) return st.error();
  auto ms = averaging_factors(options.taus, rate.size(), tau0_s);
  if (!ms) return ms.error();
  const std::vector<AvarPoint> all = overlapping_avar(rate, present, tau0_s, *ms, options.interrupt);
  if (options.interrupt != nullptr && options.interrupt->stopped()) return interrupted();
  return finish_series(rate.size(), present_samples, all, valid_runs(rate, present), tau0_s, options);
}

Result<AllanResult> finish_series(std::size_t samples, std::size_t present_samples,
                                  const std::vector<AvarPoint>& all, const std::vector<std::size_t>& runs,
                                  double tau0_s, const AllanOptions& options) {
  AllanResult result;
  result.tau0_s = tau0_s;
  result.samples = samples;
  result.present_samples = present_samples;
  std::vector<AvarPoint> avar;
  for (const AvarPoint& p : all) {
    if (p.terms > 0 && std::isfinite(p.avar)) {
      avar.push_back(p);
    } else {
      result.uncomputed_tau_s.push_back(p.tau_s);
    }
  }
  if (avar.empty()) {
    // Windows there were, and their variances overflowed: finite values too large to square, not gaps.
    if (std::any_of(all.begin(), all.end(), [](const AvarPoint& p) { return p.terms > 0; }))
      return bad_input(
          "no averaging time has a finite Allan variance: the values are too large to square "
          "(beyond about 1e150), not gaps");
    return bad_input(
        "no averaging time has a window of consecutive present samples: the gaps leave nothing to analyse");
  }
  result.points.resize(avar.size());
  for (std::size_t i = 0; i < avar.size(); ++i) {
    result.points[i].tau_s = avar[i].tau_s;
    result.points[i].terms = avar[i].terms;
  }
  // White rate noise and weights from the measured variances first; then the noise types and the
  // weights of the fitted model (iteratively reweighted: weights from the measured values favour
  // points that happen to fall low), for a fixed number of passes.
  Interrupt* interrupt = options.interrupt;
  auto stopped = [&] { return interrupt != nullptr && interrupt->stopped(); };
  set_intervals(result.points, avar, runs, options.confidence, false, interrupt);
  result.fit = fit_noise_terms(result.points, nullptr, interrupt);
  for (int pass = 0; pass < 4 && !stopped(); ++pass) {
    classify(result.points, result.fit);
    set_intervals(result.points, avar, runs, options.confidence, false, interrupt);
    result.fit = fit_noise_terms(result.points, &result.fit, interrupt);
  }
  // Intervals consistent with the reported fit.
  classify(result.points, result.fit);
  if (!stopped()) set_intervals(result.points, avar, runs, options.confidence, true, interrupt);
  if (stopped()) return interrupted();
  return result;
}

Result<LogAllan> analyze_gyro_log(const GyroLog& log, const LogAllanOptions& options) {
  LogAllan out;
  out.epochs = log.epochs();
  const bool calibrate = !log.units_dps && options.calibration != nullptr;
  out.units = (log.units_dps || calibrate) ? "deg/s" : "V";
  out.log_units_dps = log.units_dps;
  if (calibrate && options.calibration->gyro_count() < log.gyro_count) {
    return bad_input(log.source + ": the log has " + std::to_string(log.gyro_count) +
                     " gyros but the calibration only " + std::to_string(options.calibration->gyro_count()));
  }
  auto analysed = gyro_ids(options, log.gyro_count);
  if (!analysed) return analysed.error();
  const std::vector<int>& ids = *analysed;
  auto grid = uniform_grid(log.time_s, options.dt_tolerance, log.source, log.lines);
  if (!grid) return grid.error();
  out.tau0_s = grid->tau0_s;
  out.missing_epochs = grid->missing_epochs;

  const SamplingGrid& grid_ref = *grid;
  auto analyse_one = [&](int id) -> Result<GyroAllan> {
    const int g = id - 1;
    GyroAllan gyro;
    gyro.id = id;
    double bias = 0.0;
    double scale = 1.0;
    if (calibrate) {
      const GyroCalibration& cal = options.calibration->gyros[static_cast<std::size_t>(g)];
      bias = cal.bias_V;
      scale = cal.scale_factor_V_per_dps;
    }
    std::vector<double> rate(grid_ref.slots, 0.0);
    std::vector<std::uint8_t> present(grid_ref.slots, 0);
    for (std::size_t r = 0; r < log.epochs(); ++r) {
      if (!log.is_present(r, g)) continue;
      const double v = log.value(r, g);
      if (!std::isfinite(v)) {
        ++gyro.invalid;
        continue;
      }
      const std::size_t s = grid_ref.slot[r];
      rate[s] = calibrate ? (v - bias) / scale : v;
      present[s] = 1;
    }
    std::size_t delivered = 0;
    for (const std::uint8_t p : present) delivered += p;
    gyro.absent = grid_ref.slots - delivered - gyro.invalid;
    auto result = analyze_series(rate, present, grid_ref.tau0_s, without_interrupt(options.allan));
    if (!result) return gyro_error(result.error(), log.source, id, ids.size());
    gyro.result = std::move(result.value());
    return gyro;
  };

  if (Status st = analyse_gyros(
          ids.size(), [&](std::size_t i) { return analyse_one(ids[i]); }, out.gyros);
      !st)
    return st.error();
  return out;
}

// The gyros are independent: analyse them on up to two threads (the work per gyro is O(n) per τ and
// identical in any order, so the results do not depend on the thread count).
Result<std::vector<int>> gyro_ids(const LogAllanOptions& options, int gyro_count) {
  std::vector<int> ids = options.gyros;
  if (ids.empty()) {
    for (int id = 1; id <= gyro_count; ++id) ids.push_back(id);
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  for (const int id : ids) {
    if (id < 1 || id > gyro_count)
      return bad_input({kSubjectGyros, std::to_string(id)},
                       "the log has gyros 1.." + std::to_string(gyro_count));
  }
  return ids;
}

Error gyro_error(const Error& series_error, const std::string& source, int id, std::size_t analysed) {
  ErrorSubject subject = series_error.subject;
  if (subject.name.empty() && analysed > 1) subject.name = kSubjectOtherGyros;
  return bad_input(std::move(subject), source + ": gyro " + std::to_string(id) + ": " + series_error.message);
}

Status analyse_gyros(std::size_t count, const std::function<Result<GyroAllan>(std::size_t)>& analyse,
                     std::vector<GyroAllan>& out) {
  std::vector<std::optional<Result<GyroAllan>>> results(count);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < count; i = next++) results[i] = analyse(i);
  };
  const std::size_t threads =
      std::min<std::size_t>({2, count, std::max(1U, std::thread::hardware_concurrency())});
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  for (auto& r : results) {
    if (!*r) return r->error();
    out.push_back(std::move(r->value()));
  }
  return ok_status();
}

}  // namespace tetra::allan
