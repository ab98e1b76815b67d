// Late attitude references (docs/fdi.md, "Late references"): a star tracker delivers each sample 50–300 ms
// after the time it was taken, so the sample reaches the pipeline with the first epoch after its delivery,
// stamped with its own time (fdi::Epoch::reference_stamp_ns), as the service's epoch assembler hands it over.
// Seeded simulator runs of the slews scenario (10 Hz gyros, its 1 Hz, 5″ reference; slews where 300 ms is
// tens of arcseconds against 5″) straight into fdi::Pipeline:
//   * in time (the baseline), late within the fusion horizon, late beyond it (horizon 0), and late but fused
//   as
//     if taken on the epoch it reached (no horizon: what a pipeline without it would do);
//   * NEES e_a²/σ_a² over the three axes averaged over a run's sampled epochs, then over the runs (the band
//   of
//     test_mekf.cpp: [χ²_{3R}(0.025), χ²_{3R}(0.975)]/R), the fraction within 3σ, the RMS error.
#include <cmath>
#include <cstdio>
#include <deque>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "reference_horizon.hpp"
#include "tetra/core/allan_stats.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra {
namespace {

constexpr int kRuns = 6;
constexpr double kDuration_s = 900.0;  //!< both slews of the scenario and a quiet stretch
constexpr double kSampleEvery_s = 5.0;
constexpr double kSettle_s = 60.0;

enum class Delivery { kInTime, kLate, kLateAsIfNow };

struct Outcome {
  double nees_sum = 0.0;  //!< Σ over runs of the run's mean NEES
  long within = 0;
  long total = 0;
  double sq_error_sum = 0.0;  //!< [rad²] Σ |e|² over sampled epochs
  long sampled = 0;
  std::uint64_t references = 0;
  std::uint64_t delayed = 0;
  std::uint64_t too_late = 0;
  std::uint64_t accepted = 0;
  int late_events = 0;
  int other_events = 0;
  double late_event_s = 0.0;  //!< [s] the first reference_late event's statistic
  std::size_t late_detail_bytes = 0;
  double min_late_s = 1e9;  //!< [s] (delivered references only)
  double max_late_s = 0.0;

  double mean_nees() const { return nees_sum / kRuns; }
  double within_3sigma() const { return static_cast<double>(within) / static_cast<double>(total); }
  double rms_arcsec() const {
    return std::sqrt(sq_error_sum / static_cast<double>(sampled)) * kRadToDeg * 3600.0;
  }
};

//! [ns] the k-th sample's delivery delay: 50–300 ms, spread over the range (deterministic).
std::int64_t delay_ns(std::uint64_t k) {
  return 50'000'000 + static_cast<std::int64_t>((k * 7919U) % 251U) * 1'000'000;
}

void run(std::uint64_t seed, Delivery delivery, double horizon_s, Outcome& o) {
  auto sc = sim::builtin_scenario("slews");
  ASSERT_TRUE(sc.ok());
  sc->duration_s = kDuration_s;
  auto simulator = sim::Simulator::create(*sc, sim::SimOptions{seed, {}});
  ASSERT_TRUE(simulator.ok());
  sim::SimEpoch e;
  ASSERT_TRUE(simulator->next(e));
  fdi::PipelineConfig config;
  config.initial_q_RB = e.truth_q_RB;
  config.initial_sigma_deg = 0.0;
  config.reference_horizon_s = horizon_s;
  auto pipeline = fdi::Pipeline::create(sc->unit, config);
  ASSERT_TRUE(pipeline.ok());
  struct InFlight {
    std::int64_t stamp_ns;
    std::int64_t delivered_ns;
    Quaternion q_RB;
  };
  std::deque<InFlight> in_flight;
  double nees = 0.0;
  int sampled = 0;
  double next_sample_s = kSettle_s;
  do {
    fdi::Epoch epoch{e.stamp_ns, e.raw_V, e.present, std::nullopt};
    if (e.reference_q_RB) {
      ++o.references;
      if (delivery == Delivery::kInTime)
        epoch.reference_q_RB = e.reference_q_RB;
      else
        in_flight.push_back({e.stamp_ns, e.stamp_ns + delay_ns(o.references), *e.reference_q_RB});
    }
    if (!in_flight.empty() && in_flight.front().delivered_ns <= e.stamp_ns) {
      epoch.reference_q_RB = in_flight.front().q_RB;
      if (delivery == Delivery::kLate) epoch.reference_stamp_ns = in_flight.front().stamp_ns;
      const double late_s = ns_to_seconds(e.stamp_ns - in_flight.front().stamp_ns);
      o.min_late_s = std::min(o.min_late_s, late_s);
      o.max_late_s = std::max(o.max_late_s, late_s);
      in_flight.pop_front();
    }
    const auto& r = pipeline->step(epoch);
    ASSERT_TRUE(r.accepted);
    for (const auto& ev : r.events) {
      if (ev.type == fdi::EventType::kReferenceLate) {
        if (o.late_events++ == 0) o.late_event_s = ev.statistic;
        o.late_detail_bytes = std::max(o.late_detail_bytes, ev.detail.size());
      } else {
        ++o.other_events;
      }
    }
    if (e.time_s + 1e-9 < next_sample_s) continue;
    next_sample_s += kSampleEvery_s;
    const Eigen::Vector3d err = quat_log(r.attitude.q_RB.conjugate() * e.truth_q_RB);
    const Eigen::Vector3d s = r.attitude.sigma_rad;
    nees += err.cwiseQuotient(s).squaredNorm();
    ++sampled;
    for (int a = 0; a < 3; ++a) o.within += std::abs(err[a]) <= 3.0 * s[a] ? 1 : 0;
    o.total += 3;
    o.sq_error_sum += err.squaredNorm();
    ++o.sampled;
  } while (simulator->next(e));
  o.nees_sum += nees / sampled;
  const auto& c = pipeline->health().counters;
  o.delayed += c.reference_delayed;
  o.too_late += c.reference_too_late;
  o.accepted += c.reference_accepted;
}

Outcome campaign(Delivery delivery, double horizon_s, const char* name) {
  Outcome o;
  for (int k = 0; k < kRuns; ++k) run(static_cast<std::uint64_t>(2000 + k), delivery, horizon_s, o);
  std::printf(
      "[ figure ] %s: mean NEES %.3f, within 3 sigma %.4f, RMS error %.3f arcsec; references %llu, fused at "
      "their time %llu, too late %llu, used by the filter %llu; delivered %.3f..%.3f s late; reference_late "
      "events %d\n",
      name, o.mean_nees(), o.within_3sigma(), o.rms_arcsec(), static_cast<unsigned long long>(o.references),
      static_cast<unsigned long long>(o.delayed), static_cast<unsigned long long>(o.too_late),
      static_cast<unsigned long long>(o.accepted), o.min_late_s, o.max_late_s, o.late_events);
  return o;
}

double nees_lo() {
  return allan::chi2_quantile(0.025, 3.0 * kRuns) / kRuns;
}
double nees_hi() {
  return allan::chi2_quantile(0.975, 3.0 * kRuns) / kRuns;
}

// 50–300 ms late, within the default horizon (0.5 s): every sample is fused at its own time, sigma stays
// honest and the error is that of the in-time reference. Without the horizon (before this change) every one
// of them was left out (the service dropped a reference for an epoch already fused): the error was the
// gyros' alone, tens of arcseconds after the slews.
TEST(LateReference, FiftyToThreeHundredMillisecondsLateIsFusedAtItsOwnTimeAndSigmaStaysHonest) {
  const Outcome in_time = campaign(Delivery::kInTime, 0.5, "in time");
  const Outcome late = campaign(Delivery::kLate, 0.5, "50-300 ms late, horizon 0.5 s");
  EXPECT_GE(late.min_late_s, 0.05);
  EXPECT_LE(late.max_late_s, 0.31);
  EXPECT_EQ(late.delayed, late.references);
  EXPECT_EQ(late.too_late, 0U);
  EXPECT_EQ(late.late_events, 0);
  EXPECT_EQ(late.other_events, 0);
  EXPECT_GE(late.accepted, late.references - kRuns);  // the first of each run sets the attitude
  EXPECT_GE(late.mean_nees(), nees_lo());
  EXPECT_LE(late.mean_nees(), nees_hi());
  EXPECT_GE(late.mean_nees(), 0.5 * 3.0);  // not pessimistic
  EXPECT_GE(late.within_3sigma(), 0.99);
  EXPECT_LE(late.rms_arcsec(), 1.25 * in_time.rms_arcsec());
}

// Beyond the horizon (here 0: nothing stamped before its epoch is fused): counted, said once by a
// `reference_late` event carrying how late, and left out — the attitude is the gyros' alone, its sigma says
// so. A pipeline that fused the late samples as if taken on the epoch they reached would be inconsistent:
// during a 1 deg/s slew 0.3 s is 0.3° against a 5″ sigma.
TEST(LateReference, BeyondTheHorizonIsCountedAndReportedAndFusingItAsIfNowWouldBeDishonest) {
  const Outcome dropped = campaign(Delivery::kLate, 0.0, "50-300 ms late, horizon 0");
  EXPECT_EQ(dropped.delayed, 0U);
  EXPECT_EQ(dropped.too_late, dropped.references);
  EXPECT_EQ(dropped.late_events, kRuns);  // one per run: the first of a run of late samples
  EXPECT_GE(dropped.late_event_s, 0.05);
  EXPECT_LE(dropped.late_event_s, 0.31);
  EXPECT_LE(dropped.late_detail_bytes, 1023U);  // arrives whole in FdiEvent2.detail (string<1023>)
  EXPECT_EQ(dropped.accepted, 0U);
  EXPECT_GE(dropped.within_3sigma(), 0.99);
  const Outcome as_if_now = campaign(Delivery::kLateAsIfNow, 0.5, "50-300 ms late, fused as if now");
  const Outcome late = campaign(Delivery::kLate, 0.5, "50-300 ms late, horizon 0.5 s");
  EXPECT_GT(as_if_now.rms_arcsec(), 2.0 * late.rms_arcsec());
  EXPECT_GT(as_if_now.mean_nees(), 10.0 * nees_hi());
  EXPECT_GT(dropped.rms_arcsec(), 3.0 * late.rms_arcsec());  // what the horizon is worth
}

// The horizon's arithmetic alone: a reference stamped at a buffered epoch comes out rotated by the gyros'
// rotation since then (corrections left out), one older than the horizon or off every buffered stamp is too
// late, and a stamp at this epoch passes unchanged.
TEST(LateReference, TheHorizonCarriesAReferenceAlongTheGyrosRotationOnly) {
  using fdi::detail::ReferenceAge;
  fdi::detail::ReferenceHorizon h(0.05);
  const double period_s = 0.01;
  h.prepare(period_s);
  const Eigen::Vector3d omega(0.0, 0.0, 0.1);  // [rad/s]
  Quaternion q = Quaternion::Identity();
  h.record(0, q, q);
  for (int k = 1; k <= 10; ++k) {
    const Quaternion propagated = propagate(q, omega, period_s);
    // A correction at epoch 5 (a reference's update) is not motion: the horizon leaves it out.
    q = k == 5 ? propagated * quat_exp(Eigen::Vector3d(1e-3, 0.0, 0.0)) : propagated;
    h.record(k * 10'000'000, propagated, q);
  }
  const Quaternion ref = from_wxyz(1.0, 0.0, 0.0, 0.0);
  const auto placed = h.place(70'000'000, ref, 110'000'000, omega, period_s);
  ASSERT_EQ(placed.age, ReferenceAge::kDelayed);
  EXPECT_NEAR(placed.late_s, 0.04, 1e-12);
  // From epoch 7 to epoch 11: four steps about z at 0.1 rad/s.
  EXPECT_LT((canonical(placed.q_RB).coeffs() - canonical(quat_exp(omega * 0.04)).coeffs()).norm(), 1e-12);
  EXPECT_EQ(h.place(110'000'000, ref, 110'000'000, omega, period_s).age, ReferenceAge::kInTime);
  EXPECT_EQ(h.place(50'000'000, ref, 110'000'000, omega, period_s).age, ReferenceAge::kTooLate);  // 0.06 s
  fdi::detail::ReferenceHorizon none(0.0);
  none.prepare(period_s);
  none.record(0, q, q);
  EXPECT_EQ(none.place(0, ref, 10'000'000, omega, period_s).age, ReferenceAge::kTooLate);
}

}  // namespace
}  // namespace tetra
