// Each stage of the pipeline on its own (fdi/src/*.hpp): the invariants a stage promises, checked without the
// rest of the pipeline around it. The whole pipeline is guarded by the golden trace (test_golden_trace.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "bias_hypothesis.hpp"
#include "gyro_series.hpp"
#include "isolator.hpp"
#include "outlier_gate.hpp"
#include "own_noise_level.hpp"
#include "parity_bias_match.hpp"
#include "parity_detector.hpp"
#include "rate_attitude.hpp"
#include "reference_monitor.hpp"
#include "subset_cache.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {
namespace {

constexpr double kPeriod = 0.1;                   //!< [s] 10 Hz
constexpr double kArw = 3.0e-5 * kDegToRad;       //!< [rad/√s] the seed unit's N
const double kSigma = kArw / std::sqrt(kPeriod);  //!< [rad/s] per-sample noise

struct Fixture {
  PipelineConfig config;
  Calibration cal = seed_as_built_unit();
  std::vector<GyroConstants> constants;
  std::unique_ptr<SubsetCache> subsets;
  //! `quantization_deg`: the angle quantization Q of every gyro (0: the seed unit's noise section as it is).
  explicit Fixture(int n = 4, double quantization_deg = 0.0) {
    if (n == 3) cal.gyros.resize(3);
    if (quantization_deg > 0.0) {
      for (auto& g : cal.gyros) g.noise->quantization_deg = quantization_deg;
    }
    constants = *gyro_constants(cal, config);
    Eigen::VectorXd arw(n), bias(n);
    for (int i = 0; i < n; ++i) {
      arw[i] = constants[static_cast<std::size_t>(i)].arw_rad_rts;
      bias[i] = constants[static_cast<std::size_t>(i)].bias_sigma_rad_s;
    }
    subsets = std::make_unique<SubsetCache>(*GyroGeometry::create(cal.axes_B(), arw), bias, config);
    subsets->prepare(kPeriod);
  }
  //! Calibrated rates of a body rate ω (no noise).
  std::vector<double> rates(const Eigen::Vector3d& omega) const {
    std::vector<double> y;
    for (const auto& g : cal.gyros) y.push_back(g.axis_B.dot(omega));
    return y;
  }
  //! A raw epoch whose calibrated rates are `y` [rad/s].
  Epoch raw_epoch(std::int64_t ns, const std::vector<double>& y) const {
    Epoch e;
    e.stamp_ns = ns;
    for (std::size_t i = 0; i < y.size(); ++i) {
      e.raw.push_back(y[i] * constants[i].scale_V_per_rad_s + constants[i].bias_V);
      e.present.push_back(1);
    }
    return e;
  }
};

TEST(SubsetCache, ParityAnnihilatesMotionAndPseudoinverseRecoversIt) {
  // V H = 0 and H* H = I for every observable subset: a noise-free rate leaves no parity (to 1e-9 σ, rounding
  // of rates of 1 rad/s over σ ≈ 1.7e-6 rad/s) and is recovered to 1e-15 rad/s relative.
  Fixture f;
  const Eigen::Vector3d omega(0.3, -0.7, 0.5);
  const auto y = f.rates(omega);
  double p[4];
  for (GyroMask m = 0; m <= all_gyros(4); ++m) {
    const Subset& s = f.subsets->get(m);
    EXPECT_EQ(s.observable, gyro_count(m) >= 3) << m;
    if (!s.observable) continue;
    EXPECT_EQ(s.dof, gyro_count(m) - 3);
    EXPECT_LT((apply_pinv(s.pinv, m, y.data()) - omega).norm(), 1e-15 * 10);
    EXPECT_LT(apply_parity(s, m, y.data(), f.subsets->sqrt_period(), p), 1e-18);
  }
  EXPECT_FALSE(f.subsets->observable(0b0011));
}

TEST(SubsetCache, ThresholdsFollowFromTheConfiguration) {
  Fixture f;
  const Subset& s = f.subsets->get(0b1111);
  EXPECT_DOUBLE_EQ(s.chi2_threshold, chi2_threshold(f.config.false_alarm_probability, 1));
  // The fixture's unit has no wandering bias (no `bias_wander_rad_s`): the plain two-sided threshold.
  EXPECT_EQ(s.bias_wander_sigma, 0.0);
  EXPECT_NEAR(s.cusum_h, cusum_threshold(s.cusum_k, 0.1 / f.config.false_alarm_probability), 1e-5);
  // k = δ_min/2 with δ_min the smallest parity shift of a cusum_min_fault_dps step: gyros 1–3 move the
  // tetrahedron's parity by f/(√6 σ) (docs/fdi.md: k = 0.438 at 10 Hz for the nominal unit; the as-built
  // unit's axes differ by arcminutes, hence 1 %).
  EXPECT_NEAR(s.cusum_k, 0.438, 0.438 * 0.01);
}

TEST(GyroSeries, ValidatesCalibratesAndCounts) {
  Fixture f;
  GyroSeries series(f.constants, f.config);
  EpochFrame frame;
  frame.resize(4);
  Counters counters;
  Epoch e = f.raw_epoch(100, f.rates(Eigen::Vector3d(0.01, 0.0, 0.0)));
  e.present[1] = 0;
  e.raw[2] = std::numeric_limits<double>::quiet_NaN();
  e.raw[3] = 1e6;  // beyond max_abs_raw_V
  frame.now_ns = 100;
  series.ingest(e, frame, counters);
  EXPECT_EQ(frame.valid, 0b0001U);
  EXPECT_NEAR(frame.y_rad_s[0], 0.01 * f.cal.gyros[0].axis_B.x(), 1e-15);
  EXPECT_EQ(counters.samples_accepted, 1U);
  EXPECT_EQ(counters.samples_absent, 1U);
  EXPECT_EQ(counters.samples_invalid, 2U);
  EXPECT_TRUE(series.absent(2));
  EXPECT_TRUE(series.invalid(3));
}

TEST(GyroSeries, SignaturesNameTheGyroAndItsKind) {
  // Dropout after dropout_timeout_s, stuck after stuck_repeat_count identical values; a healthy gyro's robust
  // noise level is near 1 (median of 30 second differences: ±30 % covers its spread at 3σ).
  Fixture f;
  GyroSeries series(f.constants, f.config);
  EpochFrame frame;
  frame.resize(4);
  Counters counters;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, kSigma);
  Isolations found;
  bool dropout = false, stuck = false;
  double ratio = 0.0;
  for (int k = 0; k < 400 && !(dropout && stuck); ++k) {
    std::vector<double> y(4);
    for (auto& v : y) v = noise(rng);
    Epoch e = f.raw_epoch(seconds_to_ns(k * kPeriod), y);
    if (k >= 100) e.present[1] = 0;  // gyro 2 silent from 10 s
    if (k >= 200) e.raw[2] = 0.25;   // gyro 3 stuck from 20 s
    frame.now_ns = e.stamp_ns;
    series.ingest(e, frame, counters);
    series.check(frame.now_ns, 0, kPeriod, std::sqrt(kPeriod), found);
    if (k == 99) ratio = series.noise_ratio(1, std::sqrt(kPeriod));
    for (const auto& iso : found) {
      if (iso.gyro == 2) {
        EXPECT_EQ(iso.kind, FaultKind::kDropout);
        EXPECT_GE(k, 110);  // 1 s after the first missing sample
        dropout = true;
      }
      if (iso.gyro == 3) {
        EXPECT_EQ(iso.kind, FaultKind::kStuck);
        EXPECT_EQ(iso.evidence, Evidence::kRepeated);
        stuck = true;
      }
      EXPECT_TRUE(iso.gyro == 2 || iso.gyro == 3) << iso.gyro;
    }
    found.clear();
  }
  EXPECT_TRUE(dropout && stuck);
  EXPECT_NEAR(ratio, 1.0, 0.3);
}

//! A coarsely quantized unit (Q = 6e-5° on every gyro: a sample step of 2e-3 deg/s at 10 Hz, twenty times the
//! white noise) whose gyro 2 repeats one raw value for 10 s while the others see the body rate `omega(k)`
//! plus `fault(k, gyro)` [rad/s] and white noise. Returns the first isolation the signatures make (gyro 0:
//! none).
template <class Omega, class Fault>
Isolation repeat_run(Omega omega, Fault fault) {
  Fixture f(4, 6e-5);
  GyroSeries series(f.constants, f.config);
  EpochFrame frame;
  frame.resize(4);
  Counters counters;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, kSigma);
  const double stuck_raw = f.raw_epoch(0, f.rates(omega(0))).raw[1];
  Isolations found;
  for (int k = 0; k < 100; ++k) {
    std::vector<double> y = f.rates(omega(k));
    for (int i = 0; i < 4; ++i) y[static_cast<std::size_t>(i)] += noise(rng) + fault(k, i + 1);
    Epoch e = f.raw_epoch(seconds_to_ns(k * kPeriod), y);
    e.raw[1] = stuck_raw;  // gyro 2 repeats its first value
    frame.now_ns = e.stamp_ns;
    series.ingest(e, frame, counters);
    frame.usable = frame.valid;
    series.observe_motion(frame, *f.subsets);
    series.check(frame.now_ns, 0, kPeriod, std::sqrt(kPeriod), found);
    if (!found.empty()) return found.front();
  }
  return {};
}

TEST(GyroSeries, AStepOfAnotherGyroIsNotACoarseGyroStuck) {
  // The body at the orbit's pitch rate, steady: gyro 2 repeats its value as a healthy coarse gyro does. A
  // bias step of 0.03 deg/s on gyro 1 at 2 s moves the rate the others see along gyro 2's axis by about 1.1
  // times that, beyond the width a repeating gyro allows (two steps and 10σ of that view, ≈ 0.018 deg/s):
  // before, gyro 2 was called stuck 0.1 s after the step (the dispersed campaign's wrong exclusions). A step
  // explains two pieces of the run, a pulse (0.05 deg/s on gyro 3 for 0.3 s) three: no call.
  const auto orbit = [](int) { return Eigen::Vector3d(0.0, -0.06 * kDegToRad, 0.0); };
  const Isolation step =
      repeat_run(orbit, [](int k, int gyro) { return gyro == 1 && k >= 20 ? 0.03 * kDegToRad : 0.0; });
  EXPECT_EQ(step.gyro, 0) << "gyro " << step.gyro << " isolated for a step of gyro 1";
  const Isolation pulse = repeat_run(
      orbit, [](int k, int gyro) { return gyro == 3 && k >= 20 && k < 23 ? 0.05 * kDegToRad : 0.0; });
  EXPECT_EQ(pulse.gyro, 0) << "gyro " << pulse.gyro << " isolated for a pulse of gyro 3";
}

TEST(GyroSeries, ACoarseGyroStuckWhileTheBodyTurnsIsStillFound) {
  // The body accelerating at 0.05 deg/s² about gyro 2's axis from 1 s, the others healthy: their view of that
  // axis leaves every piece's width (≈ 0.018 deg/s) within about 0.4 s, so a fourth piece begins about 1.1 s
  // after the turn began. Gyro 2, repeating, is stuck (kind stuck, evidence repeated) within 3 s.
  Fixture axes(4);
  const Eigen::Vector3d h2 = axes.cal.gyros[1].axis_B.normalized();
  const auto turning = [h2](int k) {
    const double t_s = std::max(0.0, k * kPeriod - 1.0);
    return Eigen::Vector3d(Eigen::Vector3d(0.0, -0.06 * kDegToRad, 0.0) + h2 * 0.05 * kDegToRad * t_s);
  };
  const Isolation found = repeat_run(turning, [](int, int) { return 0.0; });
  EXPECT_EQ(found.gyro, 2);
  EXPECT_EQ(found.kind, FaultKind::kStuck);
  EXPECT_EQ(found.evidence, Evidence::kRepeated);
  EXPECT_GT(found.statistic, 0.0);
  // The statistic counts the repeats before the call: within 3 s at 10 Hz is at most 30 (a fourth piece
  // about 1.1 s after the turn began, then the rule's 10 repeats: about 21 expected).
  EXPECT_LE(found.statistic, 30.0) << "repeats before the call";
}

TEST(GyroSeries, SelectRankGivesTheValueNthElementGives) {
  // The noise test's median: for any window, with ties and infinities, the same value as std::nth_element
  // (exact equality: both return an element of the window, the one of that rank). 2,000 seeded windows.
  std::mt19937_64 rng(15);
  std::uniform_int_distribution<int> size(1, 40);
  std::uniform_int_distribution<int> level(0, 6);  // few distinct values: many ties
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = size(rng);
    std::vector<double> a(static_cast<std::size_t>(n));
    for (double& x : a) {
      const int l = level(rng);
      x = l == 0 ? std::numeric_limits<double>::infinity() : (trial % 2 == 0 ? l : std::abs(noise(rng)));
    }
    std::vector<double> b = a;
    const int k = n / 2;
    std::nth_element(b.begin(), b.begin() + k, b.end());
    EXPECT_EQ(tetra::fdi::detail::select_rank(a.data(), n, k), b[static_cast<std::size_t>(k)]) << "n " << n;
  }
}

TEST(GyroSeries, RankWithinDecidesAsTheValueOfThatRank) {
  // The noise test's counting decision: for any window and limits, true exactly when the element of rank k
  // lies strictly between them (no tolerance: a decision, compared with select_rank's value). Limits are
  // drawn from the window's own values and their neighbouring doubles, where an off-by-one in the counts
  // would show; many ties and infinities. 5,000 seeded windows.
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<int> size(1, 40);
  std::uniform_int_distribution<int> level(0, 6);
  std::uniform_int_distribution<int> nudge(-1, 1);
  std::normal_distribution<double> noise(0.0, 1.0);
  auto limit = [&](const std::vector<double>& a) {
    const double x = a[std::uniform_int_distribution<std::size_t>(0, a.size() - 1)(rng)];
    const int d = nudge(rng);
    return d == 0 ? x : std::nextafter(x, d < 0 ? -std::numeric_limits<double>::infinity() : x + 1.0);
  };
  for (int trial = 0; trial < 5000; ++trial) {
    const int n = size(rng);
    std::vector<double> a(static_cast<std::size_t>(n));
    for (double& x : a) {
      const int l = level(rng);
      x = l == 0 ? std::numeric_limits<double>::infinity() : (trial % 2 == 0 ? l : std::abs(noise(rng)));
    }
    const int k = n / 2;
    double low = limit(a);
    double high = limit(a);
    if (low > high) std::swap(low, high);
    std::vector<double> b = a;
    const double v = tetra::fdi::detail::select_rank(b.data(), n, k);
    EXPECT_EQ(tetra::fdi::detail::rank_within(a.data(), n, k, low, high), v > low && v < high)
        << "n " << n << " low " << low << " high " << high << " value " << v;
  }
  const std::vector<double> with_nan = {1.0, std::numeric_limits<double>::quiet_NaN(), 2.0};
  EXPECT_FALSE(tetra::fdi::detail::rank_within(with_nan.data(), 3, 1, 0.0, 10.0));  // undecided: NaN
}

TEST(OutlierGate, ASpikeIsLeftOutForOneEpochAndCounted) {
  Fixture f;
  GyroSeries series(f.constants, f.config);
  OutlierGate gate(4, f.config);
  EpochFrame frame;
  frame.resize(4);
  Counters counters;
  Isolations found;
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0.0, kSigma);
  for (int k = 0; k < 50; ++k) {
    auto y = f.rates(Eigen::Vector3d(0.0, -0.06, 0.0) * kDegToRad);
    for (auto& v : y) v += noise(rng);
    if (k == 30) y[1] += 0.05 * kDegToRad;  // one-epoch spike on gyro 2
    frame.now_ns = seconds_to_ns(k * kPeriod);
    frame.index = k;
    series.ingest(f.raw_epoch(frame.now_ns, y), frame, counters);
    frame.usable = frame.valid;
    gate.update(frame, *f.subsets, series, counters, found);
    EXPECT_EQ(frame.usable, k == 30 ? 0b1101U : 0b1111U) << k;
  }
  EXPECT_TRUE(found.empty());
  EXPECT_EQ(counters.samples_outlier, 1U);
  EXPECT_EQ(counters.spikes, 1U);
}

TEST(ParityDetector, CusumDetectsAShiftInTheoryTimeAndRestarts) {
  // A parity shift of δ = 2 σ: the CUSUM crosses h after ≈ ARL(δ − k) epochs (Siegmund; noise-free here, so
  // the deterministic crossing (h + 1.166)/(δ − k) ± 1 epoch is the check). The χ² stays silent (2² < 37).
  Fixture f;
  ParityDetector detector(4);
  detector.restart(0);
  const Subset& s = f.subsets->get(0b1111);
  EpochFrame frame;
  frame.resize(4);
  frame.usable = 0b1111;
  frame.dt_s = kPeriod;
  // y along the parity direction with |p| = 2: y = W⁺ p / √T.
  const Eigen::VectorXd w = s.parity.row(0).transpose();
  const Eigen::VectorXd y = w / w.squaredNorm() * 2.0 / f.subsets->sqrt_period();
  for (int i = 0; i < 4; ++i) frame.y_rad_s[static_cast<std::size_t>(i)] = y[i];
  Health health;
  int alarm_at = -1;
  for (int k = 0; k < 100 && alarm_at < 0; ++k) {
    frame.index = k;
    const Detection d = detector.update(frame, s, 0b1111, f.subsets->sqrt_period(), 0.0, health);
    EXPECT_TRUE(d.cusum_ran);
    EXPECT_NEAR(health.parity_residual, 2.0, 1e-9);
    if (d.alarm) {
      EXPECT_EQ(d.test, DetectionTest::kCusum);
      EXPECT_EQ(d.onset_index, 0);
      alarm_at = k;
    }
  }
  const double expected = s.cusum_h / (2.0 - s.cusum_k);
  EXPECT_NEAR(alarm_at + 1, expected, 1.0);
  detector.restart_after_alarm();
  frame.index = 200;
  EXPECT_FALSE(detector.update(frame, s, 0b1111, f.subsets->sqrt_period(), 0.0, health).alarm);
  EXPECT_NEAR(health.cusum, 2.0 - s.cusum_k, 1e-9);
}

TEST(ParityBiasMatch, WhiteParityNeverOpensTheBiasModelAndASlowErrorDoes) {
  // Four gyros (one parity row, so every gyro's column is along it). Two hours of white N(0, 1) parity — 240
  // blocks of 30 s, each at the per-block false-alarm p·n·|S| = 1e-6·300·4 — leave every gyro's bias model
  // as it is. Then a slow error on gyro 1, 5.7e-5 deg/s in amplitude with a 126-s period (the +2.8 % scale
  // change seen through the attitude control's wobble, docs/fdi.md "A slow error below the detectors"), a
  // quarter of the CUSUM's 2e-4 deg/s: matched within its 600 s (here after 60 s: a block's mean is at most
  // 0.64 of the amplitude A, its white noise σ_f = 1/√(n·a²) = 0.21·A, and the filter's prior bias
  // uncertainty v enters as v/n, so u reaches ≈ 9–12, a CUSUM step of ½(¾u − ln 4) ≈ 2.7–3.8, and two blocks
  // pass ln(1/(p·n·|S|)) = 6.7), after which
  // every gyro's slow bias carries an excess of the error's order: the largest block's f̂² − σ_f², at most
  // (0.64·A + 3σ_f)² ≈ 1.6·A² over the 20 blocks, below 2·A².
  Fixture f;
  std::vector<GyroNoiseModel> models(4);
  for (std::size_t i = 0; i < 4; ++i) {
    models[i].arw_rad_rts = f.constants[i].arw_rad_rts;
    models[i].bias_sigma_rad_s = f.constants[i].bias_sigma_rad_s;
    models[i].gm_sigma_rad_s = 1.076 * f.constants[i].bias_instability_rad_s;
  }
  Mekf filter(models);
  ParityBiasMatch match(f.config, 4);
  const Subset& s = f.subsets->get(0b1111);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  Eigen::VectorXd p(1);
  std::int64_t k = 0;
  const auto ns = [&] { return static_cast<std::int64_t>(k) * 100'000'000; };
  int findings = 0;  // the block that begins a match returns it (a noise_model event), once per match
  for (; k < 72'000; ++k) {
    p[0] = normal(rng);
    findings += match.observe(ns(), s, p, f.subsets->sqrt_period(), filter) ? 1 : 0;
  }
  EXPECT_EQ(findings, 0);
  for (int id = 1; id <= 4; ++id) EXPECT_EQ(filter.added_bias_instability(id), 0.0) << id;
  const double amplitude = 1e-6;  // [rad/s]
  const double a = f.subsets->sqrt_period() * s.parity(0, 0);
  const std::int64_t start = k;
  double matched_after_s = -1.0;
  for (; k < start + 6000; ++k) {
    const double t = static_cast<double>(k - start) * kPeriod;
    p[0] = normal(rng) + a * amplitude * std::sin(2.0 * kPi * t / 126.0);
    if (const auto found = match.observe(ns(), s, p, f.subsets->sqrt_period(), filter)) {
      ++findings;
      EXPECT_GT(found->statistic, found->threshold);
      EXPECT_GE(found->gyro, 1);
      EXPECT_LE(found->gyro, 4);
    }
    if (matched_after_s < 0.0 && filter.added_bias_instability(1) + filter.added_rate_random_walk(1) > 0.0)
      matched_after_s = t;
  }
  std::printf("slow error matched after %.0f s\n", matched_after_s);
  EXPECT_GE(matched_after_s, 0.0);
  EXPECT_EQ(findings, 1);
  for (int id = 1; id <= 4; ++id) {
    EXPECT_GT(filter.added_bias_instability(id), 0.0) << id;
    EXPECT_LT(filter.added_bias_instability(id), 2.0 * amplitude * amplitude) << id;
  }
  EXPECT_GT(filter.added_bias_instability(1), 0.1 * amplitude * amplitude);
  match.reset();
  filter.reset(0.0);
  for (int id = 1; id <= 4; ++id) EXPECT_EQ(filter.added_bias_instability(id), 0.0) << id;
}

TEST(Isolator, OnsetTestTellsTheSteppedGyroAndClassifiesIt) {
  // A 0.02 deg/s step on gyro 3 with the body still: the rate change it implies (≈ 0.01 deg/s) is beyond what
  // max_angular_acceleration_dps2 (1e-3 deg/s²) allows over the ≈ 3.5 s between the window centres, and only
  // "gyro 3 jumped" leaves a possible motion, so the onset test isolates gyro 3 (kind bias) once 20 epochs
  // follow the onset.
  Fixture f;
  GyroSeries series(f.constants, f.config);
  Isolator isolator(4, f.config);
  ParityDetector detector(4);
  EpochFrame frame;
  frame.resize(4);
  Counters counters;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, kSigma);
  Isolation found;
  Verdict verdict = Verdict::kNone;
  for (int k = 0; k < 100 && verdict == Verdict::kNone; ++k) {
    std::vector<double> y(4);
    for (auto& v : y) v = noise(rng);
    if (k >= 50) y[2] += 2e-2 * kDegToRad;
    frame.now_ns = seconds_to_ns(k * kPeriod);
    frame.index = k;
    series.ingest(f.raw_epoch(frame.now_ns, y), frame, counters);
    isolator.record(frame);
    if (k == 52) {
      Detection d{true, DetectionTest::kCusum, 30.0, 50, true};
      ASSERT_TRUE(
          isolator.open(d, frame.now_ns, k, f.subsets->get(0b1111), detector, Eigen::Vector3d::Zero()));
    }
    if (isolator.episode().active)
      verdict = isolator.decide(frame.now_ns, k, 0b1111, *f.subsets, series, found);
  }
  ASSERT_EQ(verdict, Verdict::kIsolated);
  EXPECT_EQ(found.gyro, 3);
  EXPECT_EQ(found.kind, FaultKind::kBias);
  EXPECT_EQ(found.evidence, Evidence::kOnset);
  isolator.close();
  EXPECT_FALSE(isolator.episode().active);
}

TEST(ReferenceMonitor, ADriftingGyroIsFoundAgainstTheReference) {
  // The body turns at 0.1 deg/s about Z; gyro 2 carries a 2e-3 deg/s bias. The reference (exact here) sees
  // the true rotation; gyro 2's angle drifts 0.06° per 30-s window against a σ of ≈ 2e-3°: after
  // reference_confirm_count consecutive windows it is the only one flagged.
  Fixture f;
  GyroSeries series(f.constants, f.config);
  ReferenceMonitor monitor(f.cal.axes_B(), f.config);
  EpochFrame frame;
  frame.resize(4);
  frame.dt_s = kPeriod;
  const Eigen::Vector3d omega(0.0, 0.0, 0.1 * kDegToRad);
  std::optional<ReferenceFinding> finding;
  double found_at = -1.0;
  for (int k = 0; k <= 1500 && !finding; ++k) {
    const double t = k * kPeriod;
    auto y = f.rates(omega);
    y[1] += 2e-3 * kDegToRad;
    for (std::size_t i = 0; i < 4; ++i) frame.y_rad_s[i] = y[i];
    frame.usable = 0b1111;
    frame.now_ns = seconds_to_ns(t);
    monitor.integrate(frame, 0, omega, Eigen::Vector3d::Zero(), true);
    if (k % 10 == 0) finding = monitor.update(frame.now_ns, quat_exp(omega * t), 0, series);
    if (finding) found_at = t;
  }
  ASSERT_TRUE(finding.has_value());
  EXPECT_EQ(finding->gyro, 2);
  EXPECT_FALSE(finding->scale);
  EXPECT_LE(found_at, 4 * f.config.reference_window_s);
}

//! 30 s of records at 10 Hz (a bin per 1 Hz reference sample) of a fault `fault_rad_s(t)` on gyro `id` with
//! four gyros, noise-free: the parity of every epoch and each gyro's disagreement with the reference.
SpanDisagreement fault_records(BiasHypothesis& check, const Subset& s, int id,
                               double (*fault_rad_s)(double)) {
  SpanDisagreement span;
  span.start = 0;
  span.span_s = 30.0;
  span.gyros = 0b1111;
  span.sigma_rad.fill(8.0 * kArcsecToRad);  // two 5″ reference samples and the gyro's noise, about
  Eigen::VectorXd p(1);
  for (int k = 1; k <= 300; ++k) {
    std::vector<double> y(4, 0.0);
    const double rate = fault_rad_s(k * kPeriod);
    y[static_cast<std::size_t>(id - 1)] = rate;
    double out[kMaxGyros];
    (void)apply_parity(s, s.mask, y.data(), std::sqrt(kPeriod), out);
    p[0] = out[0];
    check.record(p, s);
    span.err_rad[static_cast<std::size_t>(id - 1)] += rate * kPeriod;
    if (k % 10 == 0) check.close_bin(seconds_to_ns(k * kPeriod));
  }
  return span;
}

//! The verdict of `source`'s row on `hypothesis` in `rows` (kNoCall when it has none).
RowVerdict verdict_of(const EvidenceRows& rows, EvidenceSource source, int hypothesis) {
  for (const LedgerRow& r : rows) {
    if (r.source == source && r.hypothesis == hypothesis) return r.verdict;
  }
  return RowVerdict::kNoCall;
}

TEST(BiasHypothesis, OneGyrosPersistingFaultIsToldAndAPassingOneIsNot) {
  // Noise-free records of four gyros (d = 1: the parity fits every gyro alike, the reference tells them
  // apart). A 5e-4 deg/s step on gyro 2 for the whole span: gyro 2 explains everything (54″ against 8″ on its
  // own reference disagreement), every other gyro leaves that unexplained: margin ≫ 25, bias_fit rows H2
  // consistent, H1, H3, H4 rejected. The same mean rate as a spike in the first second: still gyro 2's, but
  // gone from the latest half: bias_persists rejects H2. Nothing at all: no margin, no row rejects.
  Fixture f;
  const Subset& s = f.subsets->get(0b1111);
  {
    BiasHypothesis check(f.constants);
    const auto span = fault_records(check, s, 2, [](double) { return 5e-4 * kDegToRad; });
    EvidenceRows rows;
    const BiasFit fit = check.best(s, span, std::sqrt(kPeriod), rows);
    EXPECT_EQ(fit.gyro, 2);
    EXPECT_NEAR(fit.size_rad_s, 5e-4 * kDegToRad, 1e-9);  // noise-free: the fit is exact to rounding
    EXPECT_GT(fit.margin, design::bias_hypothesis_margin_sigma2);
    EXPECT_EQ(rows.size(), 4);
    for (int j = 1; j <= 4; ++j) {
      EXPECT_EQ(verdict_of(rows, EvidenceSource::kBiasFit, j),
                j == 2 ? RowVerdict::kConsistent : RowVerdict::kRejected)
          << "H" << j;
    }
    SpanDisagreement late = span;
    late.start_ns = seconds_to_ns(15.0);
    late.span_s = 15.0;
    late.err_rad[1] = 5e-4 * kDegToRad * 15.0;
    EXPECT_EQ(check.persists(2, 1.0, s, late, std::sqrt(kPeriod))->verdict, RowVerdict::kConsistent);
    EXPECT_EQ(check.persists(2, -1.0, s, late, std::sqrt(kPeriod))->verdict,
              RowVerdict::kRejected);  // the other sign
  }
  {
    BiasHypothesis check(f.constants);
    const auto span = fault_records(check, s, 2, [](double t) { return t <= 1.0 ? 0.015 * kDegToRad : 0.0; });
    EvidenceRows rows;
    EXPECT_EQ(check.best(s, span, std::sqrt(kPeriod), rows).gyro, 2);
    SpanDisagreement late = span;
    late.start_ns = seconds_to_ns(15.0);
    late.span_s = 15.0;
    late.err_rad.fill(0.0);
    EXPECT_EQ(check.persists(2, 1.0, s, late, std::sqrt(kPeriod))->verdict, RowVerdict::kRejected);
  }
  {
    BiasHypothesis check(f.constants);
    const auto span = fault_records(check, s, 2, [](double) { return 0.0; });
    EvidenceRows rows;
    EXPECT_LT(check.best(s, span, std::sqrt(kPeriod), rows).margin, design::bias_hypothesis_margin_sigma2);
    for (int j = 1; j <= 4; ++j)
      EXPECT_NE(verdict_of(rows, EvidenceSource::kBiasFit, j), RowVerdict::kRejected);
  }
}

//! Feeds `seconds` of 10 Hz samples of three gyros to `level`: white noise of the model times `factor[i]` on
//! gyro i, plus a common rate `rate(t)` [rad/s]; every `drop_every`-th epoch (0: none) is missing. The gyros
//! named are collected in `named`.
template <typename Rate>
void feed(OwnNoiseLevel& level, std::mt19937_64& rng, double t0_s, double seconds,
          std::array<double, 3> factor, Rate rate, int drop_every, std::vector<int>& named) {
  std::normal_distribution<double> n01;
  EpochFrame frame;
  frame.resize(3);
  std::vector<OwnNoiseFinding> found;
  double last_s = t0_s - kPeriod;
  for (int k = 0; k * kPeriod < seconds; ++k) {
    const double t_s = t0_s + k * kPeriod;
    if (drop_every > 0 && k % drop_every == drop_every - 1) continue;
    frame.dt_s = t_s - last_s;
    frame.now_ns = seconds_to_ns(t_s);
    last_s = t_s;
    frame.valid = 0b111;
    for (int i = 0; i < 3; ++i)
      frame.y_rad_s[static_cast<std::size_t>(i)] =
          rate(t_s) + factor[static_cast<std::size_t>(i)] * kSigma * n01(rng);
    level.ingest(frame, kPeriod);
    (void)level.evaluate(0b111, std::sqrt(kPeriod), found);
    for (const auto& f : found) named.push_back(f.gyro);
  }
}

TEST(OwnNoiseLevel, EveryGyroWhoseNoiseRoseIsNamedAndAHealthyOneIsNot) {
  // Three gyros, 60 s: gyros 1 and 3 at noise x6 from the start, gyro 2 healthy — both raised ones named at
  // the same evaluation (each its own event), with λ near 36, gyro 2 never.
  Fixture f(3);
  OwnNoiseLevel level(f.constants, f.config);
  std::mt19937_64 rng(5);
  std::vector<int> named;
  feed(
      level, rng, 0.0, 60.0, {6.0, 1.0, 6.0}, [](double) { return 0.0; }, 0, named);
  EXPECT_EQ(named, (std::vector<int>{1, 3}));
  EXPECT_TRUE(level.named(1) && level.named(3) && !level.named(2));
  // λ within 36 ± 50 %: the level of one window of 30 correlated values is good to about ±20 % in σ.
  EXPECT_GT(level.ratio(1), 18.0);
  EXPECT_LT(level.ratio(1), 54.0);
  EXPECT_EQ(level.ratio(2), 1.0);
}

TEST(OwnNoiseLevel, ANamedGyroBackToNormalIsNamedNoMoreAndForgetClearsIt) {
  // Gyro 2 at x8 for 20 s, then healthy for 60 s: named, then (its smoothed level below 1.5) named no more,
  // λ 1; named again at x8, then `forget` clears it at once; `reset` too.
  Fixture f(3);
  OwnNoiseLevel level(f.constants, f.config);
  std::mt19937_64 rng(9);
  std::vector<int> named;
  const auto still = [](double) { return 0.0; };
  feed(level, rng, 0.0, 20.0, {1.0, 8.0, 1.0}, still, 0, named);
  ASSERT_TRUE(level.named(2));
  feed(level, rng, 20.0, 60.0, {1.0, 1.0, 1.0}, still, 0, named);
  EXPECT_FALSE(level.named(2));
  EXPECT_EQ(level.ratio(2), 1.0);
  feed(level, rng, 80.0, 20.0, {1.0, 8.0, 1.0}, still, 0, named);
  EXPECT_EQ(named, (std::vector<int>{2, 2}));
  level.forget(2);
  EXPECT_FALSE(level.named(2));
  EXPECT_EQ(level.ratio(2), 1.0);
  feed(level, rng, 100.0, 10.0, {1.0, 8.0, 1.0}, still, 0, named);
  ASSERT_TRUE(level.named(2));
  level.reset();
  EXPECT_FALSE(level.named(2));
}

TEST(OwnNoiseLevel, AMissingEpochInASlewReadsAsNothing) {
  // Healthy gyros, a steady acceleration of 2.8 deg/s² (the families' fastest slew's peak) for 60 s, every
  // 7th epoch missing: the series restarts at the missing epoch (its interval is off by a period), and the
  // weights over the stamps' times leave a cubic in time nothing however the epochs fall; nothing is named.
  // The same samples stamped as if evenly spaced (stamps that hide the missing epochs) put a·T ≈ 0.28 deg/s,
  // some 3,000 times the white level, into the differences across them: all three gyros named.
  Fixture f(3);
  const auto slew = [](double t_s) { return 2.8 * kDegToRad * t_s; };
  std::vector<int> named;
  {
    OwnNoiseLevel level(f.constants, f.config);
    std::mt19937_64 rng(3);
    feed(level, rng, 0.0, 60.0, {1.0, 1.0, 1.0}, slew, 7, named);
    EXPECT_TRUE(named.empty());
  }
  OwnNoiseLevel level(f.constants, f.config);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  EpochFrame frame;
  frame.resize(3);
  std::vector<OwnNoiseFinding> found;
  int names = 0;
  int stamped = 0;
  for (int k = 0; k * kPeriod < 60.0; ++k) {
    if (k % 7 == 6) continue;
    frame.valid = 0b111;
    frame.dt_s = kPeriod;
    frame.now_ns = seconds_to_ns(kPeriod * stamped++);
    for (int i = 0; i < 3; ++i)
      frame.y_rad_s[static_cast<std::size_t>(i)] = slew(k * kPeriod) + kSigma * n01(rng);
    level.ingest(frame, kPeriod);
    (void)level.evaluate(0b111, std::sqrt(kPeriod), found);
    names += static_cast<int>(found.size());
  }
  EXPECT_EQ(names, 3);
}

TEST(RateAttitude, ConstantRatePropagatesExactly) {
  // q(t) = exp(ω t) for a constant rate (exact exponential map, trapezoid of equal rates): 600 steps leave
  // less than 1e-12 rad of rounding.
  Fixture f;
  f.config.initial_sigma_deg = 0.0;
  std::vector<GyroNoiseModel> white(4);  // white noise only: the filter's σ is the ARW's
  for (std::size_t i = 0; i < 4; ++i) white[i].arw_rad_rts = f.constants[i].arw_rad_rts;
  RateAttitude attitude(f.config, white);
  attitude.reset(Quaternion::Identity());
  EpochFrame frame;
  frame.resize(4);
  frame.usable = 0b1111;
  frame.dt_s = kPeriod;
  const Eigen::Vector3d omega(0.01, -0.02, 0.03);
  const auto y = f.rates(omega);
  for (std::size_t i = 0; i < 4; ++i) frame.y_rad_s[i] = y[i];
  const Subset& s = f.subsets->get(0b1111);
  attitude.measure(s, frame);
  attitude.finish_epoch();
  for (int k = 1; k <= 600; ++k) {
    frame.now_ns = seconds_to_ns(k * kPeriod);
    attitude.measure(s, frame);
    attitude.propagate(frame, s, &s, Eigen::Vector3d::Zero(), kPeriod);
    attitude.finish_epoch();
  }
  EXPECT_LT(angle_between(attitude.q_RB(), quat_exp(omega * 60.0)), 1e-12);
  // σ² summed over the axes: Σ N_a²·t (the error covariance turns with the body, its trace does not; the
  // process noise H*·diag(N²)·H*ᵀ has the trace of diag((HᵀR⁻¹H)⁻¹)). Relative 1e-12: rounding of 600 sums.
  const double expect = s.arw_sq_rad2_s.sum() * 60.0;
  EXPECT_NEAR(attitude.sigma_rad().squaredNorm(), expect, 1e-12 * expect);
}

}  // namespace
}  // namespace tetra::fdi::detail
