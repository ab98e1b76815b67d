// The attitude reference as a sensor that can fail (docs/fdi.md, "Reference consistency"): a late, noisy,
// slowly biased or mis-identified star tracker, simulated by sim/'s reference failure modes, is rejected with
// `reference_rejected` and the reason; sigma then comes from the gyros and covers the error; the attitude is
// never set onto a reference the gyros contradict; a healthy reference is never rejected.
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra {
namespace {

struct Outcome {
  std::vector<fdi::FdiEvent> events;
  int rejected = 0;  //!< reference_rejected events
  fdi::ReferenceCheck first_why = fdi::ReferenceCheck::kNone;
  double first_rejected_s = -1.0;  //!< [s]
  int within_3sigma = 0;           //!< (epoch, axis) with |e| ≤ 3σ, sampled every second from kSettle_s
  int total = 0;
  double worst_ratio = 0.0;             //!< largest |e|/σ over those samples
  int beyond_protection = 0;            //!< sampled (epoch, axis) with |e| above the protection level
  double worst_protection_ratio = 0.0;  //!< largest |e|/PL
  double first_detected_s = -1.0;
  int within_after = 0;  //!< as within_3sigma, after the first rejection or detection
  int total_after = 0;
  double first_accepted_s = -1.0;  //!< [s] first reference_accepted
  double final_error_arcsec = 0.0;
  fdi::Health health;
};

constexpr double kSettle_s = 20.0;  //!< statistics from here (the reference's first samples set the attitude)

sim::Scenario scenario(double duration_s, bool slew) {
  auto sc = sim::builtin_scenario("slews");
  EXPECT_TRUE(sc.ok());
  sc->duration_s = duration_s;
  sc->motion.slews.clear();
  // 30° about X in 20 s (1.5 deg/s), then −45° about Z in 15 s: agile motion a late reference cannot hide.
  if (slew)
    sc->motion.slews = {{Eigen::Vector3d::UnitX(), 30.0, 60.0, 20.0},
                        {Eigen::Vector3d::UnitZ(), -45.0, 150.0, 15.0}};
  return *sc;
}

Outcome run(const sim::Scenario& sc, std::uint64_t seed, fdi::PipelineConfig config = {}) {
  Outcome out;
  auto simulator = sim::Simulator::create(sc, sim::SimOptions{seed, {}});
  EXPECT_TRUE(simulator.ok());
  sim::SimEpoch se;
  if (!simulator->next(se)) return out;
  config.initial_q_RB = se.truth_q_RB;
  auto pipeline = fdi::Pipeline::create(sc.unit, config);
  EXPECT_TRUE(pipeline.ok());
  double next_sample_s = kSettle_s;
  do {
    const auto& r = pipeline->step(fdi::Epoch{se.stamp_ns, se.raw_V, se.present, se.reference_q_RB});
    for (const auto& e : r.events) {
      out.events.push_back(e);
      if (e.type == fdi::EventType::kDetected && out.first_detected_s < 0.0)
        out.first_detected_s = ns_to_seconds(e.stamp_ns);
      if (e.type == fdi::EventType::kReferenceAccepted && out.first_accepted_s < 0.0)
        out.first_accepted_s = ns_to_seconds(e.stamp_ns);
      if (e.type != fdi::EventType::kReferenceRejected) continue;
      if (out.rejected++ == 0) {
        out.first_why = e.why;
        out.first_rejected_s = ns_to_seconds(e.stamp_ns);
      }
    }
    if (!r.accepted) continue;
    const Eigen::Vector3d err = quat_log(se.truth_q_RB.conjugate() * r.attitude.q_RB);
    if (se.time_s >= next_sample_s) {
      next_sample_s += 1.0;
      for (int a = 0; a < 3; ++a) {
        const double ratio = std::abs(err[a]) / r.attitude.sigma_rad[a];
        out.worst_ratio = std::max(out.worst_ratio, ratio);
        out.within_3sigma += ratio <= 3.0 ? 1 : 0;
        if (out.first_rejected_s >= 0.0 || out.first_detected_s >= 0.0) {
          out.within_after += ratio <= 3.0 ? 1 : 0;
          ++out.total_after;
        }
        const double pl_ratio = std::abs(err[a]) / r.attitude.protection_level_rad[a];
        out.worst_protection_ratio = std::max(out.worst_protection_ratio, pl_ratio);
        out.beyond_protection += pl_ratio > 1.0 ? 1 : 0;
        ++out.total;
      }
    }
    out.final_error_arcsec = err.norm() * (1.0 / kArcsecToRad);
  } while (simulator->next(se));
  out.health = pipeline->health();
  return out;
}

std::string summary(const Outcome& o) {
  char text[256];
  std::snprintf(
      text, sizeof text,
      "rejected %d (first %s at %.1f s), within 3 sigma %.4f, worst %.1f sigma, final error %.2f arcsec, "
      "reinitialized %llu, state %s, nis %.2f",
      o.rejected, fdi::to_string(o.first_why), o.first_rejected_s,
      o.total ? static_cast<double>(o.within_3sigma) / o.total : 1.0, o.worst_ratio, o.final_error_arcsec,
      static_cast<unsigned long long>(o.health.counters.reference_reinitialized),
      fdi::to_string(o.health.reference_state), o.health.reference_nis);
  std::string s = text;
  for (const auto& e : o.events) s += "\n  " + fdi::to_json(e, 4);
  return s;
}

double fraction(int within, int total) {
  return total ? static_cast<double>(within) / total : 1.0;
}

// Tolerances: 97 % within 3σ is the campaign's criterion (99.73 % for a consistent Gaussian error; the
// sampled epochs of one run are correlated, so a run's fraction scatters around it); times are the simulated
// failure's own (1 Hz samples: ±1 s).

TEST(ReferenceConsistency, AHealthyReferenceIsNeverRejected) {
  // Orbit with two agile slews (30° in 20 s about X, 45° in 15 s about Z), 1 Hz 5″ reference, three seeds:
  // the tests' design is p = 1e-9 per sample, 300 samples per run: a rejection would be a false alarm.
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome o = run(scenario(300.0, true), seed);
    EXPECT_EQ(o.rejected, 0) << summary(o);
    EXPECT_EQ(o.health.reference_state, fdi::ReferenceState::kAccepted);
    EXPECT_GT(o.health.reference_nis, 0.3) << summary(o);  // ≈ 1 (0.95..1.13 measured): the block's NIS/dof
    EXPECT_LT(o.health.reference_nis, 3.0) << summary(o);
    EXPECT_GE(fraction(o.within_3sigma, o.total), 0.97) << summary(o);
  }
}

TEST(ReferenceConsistency, ALateReferenceIsRejectedForLagAtTheFirstSlew) {
  // 0.2 s late: at the orbit's steady pitch rate an offset of 43″ no test can see (an attitude offset); the
  // first slew (1.5 deg/s from 60 s) moves the innovations with the rate: `lag` within two samples, never
  // used again (the rate changes since could not show it consistent), sigma from the gyros covers the error.
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.latency_s = 0.2;
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    const Outcome o = run(sc, seed);
    ASSERT_GE(o.rejected, 1) << summary(o);
    EXPECT_EQ(o.first_why, fdi::ReferenceCheck::kLag) << summary(o);
    EXPECT_GE(o.first_rejected_s, 60.0) << summary(o);
    EXPECT_LE(o.first_rejected_s, 62.0) << summary(o);
    EXPECT_EQ(o.health.counters.reference_reinitialized, 0U);
    EXPECT_EQ(o.health.reference_state, fdi::ReferenceState::kRejected);
    EXPECT_GE(fraction(o.within_after, o.total_after), 0.97) << summary(o);
  }
}

TEST(ReferenceConsistency, ANoisyReferenceIsRejectedAndSigmaComesFromTheGyros) {
  // 20″ of noise where 5″ is configured (4×): rejected within its first samples; what the used samples put
  // in the attitude (their innovations' excess second moment, and the first sample's, which set it) widens
  // sigma; it is not used again (the tests could not tell a noisy reference once the attitude is looser
  // than the reference claims to be).
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.noise_arcsec = 20.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome o = run(sc, seed);
    ASSERT_GE(o.rejected, 1) << summary(o);
    EXPECT_LE(o.first_rejected_s, 5.0) << summary(o);
    EXPECT_EQ(o.health.counters.reference_reinitialized, 0U);
    EXPECT_GE(fraction(o.within_after, o.total_after), 0.97) << summary(o);
  }
}

TEST(ReferenceConsistency, AReferenceSomewhatNoisierThanConfiguredIsUsedAgainWithItsNoiseReestimated) {
  // 8″ of noise where 5″ is configured (1.6×): rejected (`nis`); its noise re-estimated from successive
  // innovations (upper bound at 1 − 1e-3, at most reference_noise_max_factor = 3 × 5″) and the reference used
  // again with it — 30 s for the estimate, 30 s of passing every test against it: 60..90 s after the
  // rejection (seeds 1..3: 61 s measured; 100 % of sampled axes within 3σ); sigma honest throughout.
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.noise_arcsec = 8.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome o = run(sc, seed);
    ASSERT_GE(o.rejected, 1) << summary(o);
    EXPECT_EQ(o.first_why, fdi::ReferenceCheck::kNis) << summary(o);
    ASSERT_GT(o.first_accepted_s, o.first_rejected_s) << summary(o);
    EXPECT_LE(o.first_accepted_s - o.first_rejected_s, 90.0) << summary(o);
    EXPECT_EQ(o.health.reference_state, fdi::ReferenceState::kAccepted) << summary(o);
    EXPECT_EQ(o.health.counters.reference_reinitialized, 0U);
    EXPECT_GE(fraction(o.within_3sigma, o.total), 0.97) << summary(o);
  }
  // 4× the configured noise is beyond reference_noise_max_factor: never used again.
  sc.reference.noise_arcsec = 20.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome o = run(sc, seed);
    ASSERT_GE(o.rejected, 1) << summary(o);
    EXPECT_LT(o.first_accepted_s, 0.0) << summary(o);
  }
}

TEST(ReferenceConsistency, ARejectionAGyroFaultMayHaveCausedIsWithdrawnAtItsDetection) {
  // examples/sim/calibrated_unit.yaml (its stated 1σ raises the CUSUM's reference), the orbit, the 1 Hz 5″
  // reference, gyro 2 stuck at 300 s (seed 4): its error grows with the rate's change along its axis and
  // fails the reference's `nis` test at 359 s, before the parity detects it at 366 s. The rejection is
  // withdrawn at the detection (a `reference_accepted` at that epoch) and the reference's windows isolate
  // gyro 2 (382 s measured); kept rejected, the episode ended unisolated.
  auto sc = sim::parse_scenario(
      "scenario: orbit\nduration_s: 600\nrate_hz: 10\norbit_period_s: 6000\nunit: sim/calibrated_unit.yaml\n"
      "reference: {rate_hz: 1, noise_arcsec: 5}\nfaults: [\"gyro=2,kind=stuck,at=300\"]\n",
      "stuck-after-rejection", test::source_path("examples"));
  ASSERT_TRUE(sc.ok()) << describe(sc.error());
  const Outcome o = run(*sc, 4);
  double detected_s = -1.0;
  double withdrawn_s = -1.0;
  std::optional<int> isolated;
  for (const auto& e : o.events) {
    const double t = ns_to_seconds(e.stamp_ns);
    if (e.type == fdi::EventType::kDetected && detected_s < 0.0) detected_s = t;
    if (e.type == fdi::EventType::kReferenceAccepted && withdrawn_s < 0.0) {
      withdrawn_s = t;
      // The arbiter's rule over the rejection's rows once the parity's rows make no call: a gyro's
      // hypothesis stands beside Href, so the reference no longer stands alone.
      EXPECT_EQ(fdi::reference_ruling_of(e), fdi::ReferenceDecision::kNoCall) << summary(o);
    }
    if (e.type == fdi::EventType::kReferenceRejected) {  // each rejection rebuilt from its event alone
      EXPECT_EQ(fdi::reference_ruling_of(e), fdi::ReferenceDecision::kReject) << summary(o);
    }
    if (e.type == fdi::EventType::kIsolated && !isolated) isolated = e.gyro;
  }
  ASSERT_GE(o.first_rejected_s, 300.0) << summary(o);
  EXPECT_EQ(o.first_why, fdi::ReferenceCheck::kNis) << summary(o);
  ASSERT_GT(detected_s, o.first_rejected_s) << summary(o);
  EXPECT_EQ(withdrawn_s, detected_s) << summary(o);
  EXPECT_EQ(isolated, std::optional<int>(2)) << summary(o);
}

TEST(ReferenceConsistency, AMisidentifiedReferenceIsAJumpNeverSetsTheAttitudeAndIsUsedAgain) {
  // 0.5° off for 12 s from 100 s: `jump` at its first sample; the attitude stays the gyros' (never set onto
  // it); used again 30 s after the episode ends (one block of the tests, reference_window_s), the error
  // back to arcseconds.
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.misid_deg = 0.5;
  sc.reference.misid_at_s = 100.0;
  sc.reference.misid_duration_s = 12.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome o = run(sc, seed);
    ASSERT_EQ(o.rejected, 1) << summary(o);
    EXPECT_EQ(o.first_why, fdi::ReferenceCheck::kJump) << summary(o);
    for (const auto& e : o.events) {  // a jump's rows reject every gyro's hypothesis by the test itself
      if (e.type == fdi::EventType::kReferenceRejected) {
        EXPECT_EQ(fdi::reference_ruling_of(e), fdi::ReferenceDecision::kReject) << summary(o);
      }
    }
    EXPECT_EQ(o.first_rejected_s, 100.0) << summary(o);
    EXPECT_GE(o.first_accepted_s, 112.0 + 30.0) << summary(o);
    EXPECT_LE(o.first_accepted_s, 112.0 + 32.0) << summary(o);
    EXPECT_EQ(o.health.counters.reference_reinitialized, 0U);
    EXPECT_LT(o.final_error_arcsec, 5.0) << summary(o);  // 1.3..2.1″ measured; the reference's σ is 5″
    EXPECT_GE(fraction(o.within_3sigma, o.total), 0.97) << summary(o);
  }
}

TEST(ReferenceConsistency, ABiasStepIsRejectedAndSigmaCoversIt) {
  // A 30″ bias appearing at 30 s (6σ of one sample): rejected within 5 s, sigma from the gyros thereafter.
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.bias_arcsec = 30.0;
  sc.reference.bias_at_s = 30.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome o = run(sc, seed);
    ASSERT_GE(o.rejected, 1) << summary(o);
    EXPECT_GE(o.first_rejected_s, 30.0) << summary(o);
    EXPECT_LE(o.first_rejected_s, 35.0) << summary(o);
    EXPECT_GE(fraction(o.within_after, o.total_after), 0.97) << summary(o);
  }
}

TEST(ReferenceConsistency, ASmallBiasStepIsCaughtByTheStepTestAndSigmaCarriesIt) {
  // A bias stepping by 8, 10, 12 or 15″ at 100 s (1.6–3σ of one sample; the jump test needs 6.7σ), the orbit
  // with its slews, eight seeds each: the filter takes such a step in over ~37 samples and no one sample or
  // long mean shows it; the step test fits the absorption (docs/fdi.md, "Reference consistency"). From 12″ on
  // every run is rejected for `step` within 30 s (measured up to 24 s) and from then on 97 % of sampled axes
  // are within 3σ (the step's |ĉ| in sigma); at 8–10″ the caught share is printed (measured 0 and 6 of 8),
  // the rest followed within the noise (Limits).
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.bias_at_s = 100.0;
  for (const double arcsec : {8.0, 10.0, 12.0, 15.0}) {
    sc.reference.bias_arcsec = arcsec;
    int caught = 0;
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      const Outcome o = run(sc, seed);
      const bool step = o.rejected >= 1 && o.first_why == fdi::ReferenceCheck::kStep;
      caught += step ? 1 : 0;
      if (arcsec < 12.0) continue;
      ASSERT_TRUE(step) << arcsec << " arcsec seed " << seed << ": " << summary(o);
      EXPECT_GE(o.first_rejected_s, 100.0) << summary(o);
      EXPECT_LE(o.first_rejected_s, 130.0) << summary(o);
      EXPECT_GE(fraction(o.within_after, o.total_after), 0.97) << summary(o);
    }
    std::printf("bias step %.0f arcsec: %d of 8 rejected for step\n", arcsec, caught);
  }
}

TEST(ReferenceConsistency, WithThreeGyrosTheReferenceDetectsASecondFault) {
  // Redundancy exhausted (three gyros, no parity): a 3e-4 deg/s bias on gyro 1 from 60 s is detected by the
  // reference's tests (`detected`, test `reference`; 22 s after onset in this run) and the filter's bias
  // states open to it; the reference stays in use.
  sim::Scenario sc = scenario(300.0, false);
  sc.unit.gyros.pop_back();
  sim::FaultSpec f;
  f.gyro = 1;
  f.kind = sim::FaultKind::kBias;
  f.at_s = 60.0;
  f.size = 3e-4;
  sc.faults = {f};
  const Outcome o = run(sc, 5);
  ASSERT_GE(o.first_detected_s, 60.0) << summary(o);
  EXPECT_LE(o.first_detected_s, 90.0) << summary(o);
  EXPECT_EQ(o.rejected, 0) << summary(o);
  // Before the detection the error reaches 14.7σ (the bias is in no state of the filter yet): sigma is
  // honest only from the detection on.
  EXPECT_GE(fraction(o.within_after, o.total_after), 0.97) << summary(o);
}

// The reference's stated budget ("Stated budget"): what no test of its samples can show — a latency at a
// steady rate, a bias the filter follows within its noise — is carried by sigma when the specification states
// it. Each case first runs without the budget, where the same error is well beyond 3σ (the limit the budget
// answers: the test could not pass by a loose criterion), then with it.

TEST(ReferenceBudget, ALatencyWithinTheStatedBoundIsCoveredBeforeTheSlewShowsIt) {
  // 0.2 s late, the specification's bound 0.2 s: at the orbit's steady pitch rate the 43″ offset is within
  // 3σ from the start (50σ without the budget); the first slew's `lag` rejection still happens.
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.latency_s = 0.2;
  const Outcome unstated = run(sc, 1);
  EXPECT_GT(unstated.worst_ratio, 10.0) << summary(unstated);  // 50σ measured: a margin of 5 on the limit
  fdi::PipelineConfig config;
  config.reference_latency_max_s = 0.2;
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    const Outcome o = run(sc, seed, config);
    EXPECT_EQ(o.first_why, fdi::ReferenceCheck::kLag) << summary(o);
    EXPECT_GE(fraction(o.within_3sigma, o.total), 0.97) << summary(o);
    // A 3σ criterion with one sampled axis-epoch's slack: the offset itself is ≤ 1σ of the budget's term.
    EXPECT_LE(o.worst_ratio, 4.0) << summary(o);
  }
}

TEST(ReferenceBudget, ABiasTheFilterFollowsIsCoveredWhenStated) {
  // A 10″ bias from 30 s (2σ of one 5″ sample): while the orbit's rate is steady no test sees it (the filter
  // follows it within its noise; docs/fdi.md, Limits) and the error grows to 10″ under a σ of ~1″. With a
  // stated 1σ of 10″ (the error is then 1σ of the budget) every sampled axis is within 3σ, before and after
  // the `bias` test may reject it once a slew changes what the filter follows.
  sim::Scenario sc = scenario(300.0, true);
  sc.reference.bias_arcsec = 10.0;
  sc.reference.bias_at_s = 30.0;
  const Outcome unstated = run(sc, 1);
  EXPECT_GT(unstated.worst_ratio, 5.0) << summary(unstated);  // well beyond 3σ: the budget is what covers it
  fdi::PipelineConfig config;
  config.reference_bias_arcsec = 10.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome o = run(sc, seed, config);
    EXPECT_EQ(o.health.counters.reference_reinitialized, 0U) << summary(o);
    EXPECT_GE(fraction(o.within_3sigma, o.total), 0.97) << summary(o);
    EXPECT_LE(o.worst_ratio, 3.0) << summary(o);
  }
}

//! Three gyros (gyro 4 absent) and the reference, `kind` of `size` on gyro `gyro` from 60 s, `duration_s`.
sim::Scenario three_gyros_with(sim::FaultKind kind, int gyro, double size, double duration_s) {
  sim::Scenario sc = scenario(duration_s, false);
  sc.unit.gyros.pop_back();
  sim::FaultSpec f;
  f.gyro = gyro;
  f.kind = kind;
  f.at_s = 60.0;
  f.size = size;
  sc.faults = {f};
  return sc;
}

//! [s] the first `detected` event whose text holds `words`, or −1.
double detection_with_s(const Outcome& o, const std::string& words) {
  for (const auto& e : o.events) {
    if (e.type == fdi::EventType::kDetected && e.detail.find(words) != std::string::npos)
      return ns_to_seconds(e.stamp_ns);
  }
  return -1.0;
}

//! [s] the first `detected` event that names gyro `id` along its rate axis (the three-gyro innovation test),
//! or −1.
double named_detection_s(const Outcome& o, int id) {
  return detection_with_s(o, "along gyro " + std::to_string(id) + "'s");
}

//! [s] the first `detected` event that names gyro `id` by its own noise level (three gyros), or −1.
double own_level_named_s(const Outcome& o, int id) {
  return detection_with_s(o, "gyro " + std::to_string(id) + "'s own noise level");
}

int exclusions(const Outcome& o) {
  int n = 0;
  for (const auto& e : o.events) n += e.type == fdi::EventType::kIsolated ? 1 : 0;
  return n;
}

TEST(ThreeGyroNoise, ANoiseIncreaseIsNamedWithinSecondsAndSigmaCoversIt) {
  // Three gyros, noise x5 or x10 on each gyro in turn from 60 s, 240 s, with the reference and without, two
  // seeds: the gyro's own fourth differences name it (docs/fdi.md, "Three gyros: a gyro's own noise level")
  // 2.3–3.3 s after onset (measured), it is never excluded, and its noise in the filter follows its level:
  // 99.8–100 % within 3σ from then on (measured). Before, only the reference's innovations could name it,
  // 51–441 s after onset, and without a reference nothing did (sigma short by the noise factor). Bounds:
  // named within 10 s (a window of 30 values at 10 Hz is 3 s, plus up to 4 s for its median to cross the
  // limit at x5), and the campaign's criterion, 97 % within 3σ, after.
  for (const bool reference : {true, false}) {
    for (const double factor : {5.0, 10.0}) {
      for (const int gyro : {1, 2, 3}) {
        for (const std::uint64_t seed : {1u, 2u}) {
          sim::Scenario sc = three_gyros_with(sim::FaultKind::kNoise, gyro, factor, 240.0);
          if (!reference) sc.reference = sim::ReferenceOptions{};
          const Outcome o = run(sc, seed);
          const std::string what = (reference ? "reference, x" : "no reference, x") + std::to_string(factor) +
                                   " gyro " + std::to_string(gyro) + " seed " + std::to_string(seed) + ": ";
          const double t = own_level_named_s(o, gyro);
          ASSERT_GE(t, 60.0) << what << summary(o);
          EXPECT_LE(t, 70.0) << what << summary(o);
          EXPECT_EQ(exclusions(o), 0) << what << summary(o);
          EXPECT_GE(fraction(o.within_after, o.total_after), 0.97) << what << summary(o);
        }
      }
    }
  }
}

TEST(ThreeGyroNoise, AgileSlewsJitterAndACoarselyQuantizedUnitNameNoHealthyGyro) {
  // Three healthy gyros, 300 s of agile slews (45° in 10 s, the perturbation families' fastest: 4.5 deg/s
  // at 0.1 Hz, which the fourth difference passes at 7e-5 deg/s, 9 % of a 3e-5 deg/√s gyro's white level)
  // about X, Y, Z and about the axis perpendicular to gyros 2 and 3 (a motion only gyro 1 sees), with no
  // quantization and with an angle quantization of 1e-5 deg (a step of 3.6σ: repeated values are the norm),
  // with and without a sampling jitter of ±5 ms (each sample the rate at its own, stamped instant: on even
  // weights a slew's acceleration times the jitter read as noise, up to 20 times the white level, and named
  // healthy gyros; the weights over the stamps' times leave nothing of it), four seeds each: no gyro is
  // named, no detection at all. The level measured at most 2.4 over the runs without jitter or quantization
  // (3,564 evaluations, median 1.05), as white noise alone gives it (beyond 2.5 once in 2e4 evaluations); the
  // limit is noise_high_ratio, 4.
  const Eigen::Vector3d across_2_3 = Eigen::Vector3d(0.42638, 0.78516, -0.44914)
                                         .cross(Eigen::Vector3d(0.51389, -0.74179, -0.43088))
                                         .normalized();
  for (const double jitter_s : {0.0, 0.005}) {
    for (const double quantization_deg : {0.0, 1e-5}) {
      for (const std::uint64_t seed : {1u, 2u, 3u, 4u}) {
        sim::Scenario sc = scenario(300.0, false);
        sc.unit.gyros.pop_back();
        sc.jitter_s = jitter_s;
        double start_s = 30.0;
        for (const Eigen::Vector3d& axis :
             {Eigen::Vector3d(Eigen::Vector3d::UnitX()), Eigen::Vector3d(Eigen::Vector3d::UnitY()),
              Eigen::Vector3d(Eigen::Vector3d::UnitZ()), across_2_3, Eigen::Vector3d(-across_2_3)}) {
          sc.motion.slews.push_back({axis, 45.0, start_s, 10.0});
          start_s += 50.0;
        }
        for (auto& g : sc.unit.gyros) {
          if (!g.noise) g.noise = GyroNoise{};
          g.noise->quantization_deg = quantization_deg;
        }
        fdi::PipelineConfig config;
        config.sample_period_s = 0.1;  // as a service with jitter configures it
        const Outcome o = run(sc, seed, config);
        EXPECT_LT(o.first_detected_s, 0.0) << "jitter " << jitter_s << " s, quantization " << quantization_deg
                                           << " seed " << seed << ": " << summary(o);
      }
    }
  }
}

TEST(ReferenceConsistency, WithThreeGyrosANoiseIncreaseIsDetectedAndSigmaMatchesIt) {
  // Three gyros, noise x10 on gyro 2 from 60 s, 600 s, twelve seeds, the reference's innovations alone (the
  // own noise level's limit, noise_high_ratio, set out of reach: it names the gyro within seconds, above):
  // the innovations along gyro 2's rate axis raise their 10-s block means' CUSUM (docs/fdi.md, "Three gyros:
  // a noise increase or a ramp"), the gyro is named and its noise in the filter matched to the innovations
  // from then on. Named 51–441 s after onset (median 166 s), 99.55–100 % within 3σ after. Without this
  // test, the block NIS or mean-innovation test fired in 7 of the 12 (136–374 s after onset, no gyro named)
  // and sigma stayed short (74–89 % within 3σ over the run). Bounds: named within 500 s of onset, and from
  // the detection on the campaign's criterion, 97 % within 3σ.
  fdi::PipelineConfig innovations_only;
  innovations_only.noise_high_ratio = 1e9;
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 10u, 11u, 12u}) {
    const Outcome o = run(three_gyros_with(sim::FaultKind::kNoise, 2, 10.0, 600.0), seed, innovations_only);
    const double t = named_detection_s(o, 2);
    ASSERT_GE(t, 60.0) << summary(o);
    EXPECT_LE(t, 560.0) << summary(o);
    EXPECT_EQ(o.rejected, 0) << summary(o);
    EXPECT_GE(fraction(o.within_after, o.total_after), 0.97) << summary(o);
  }
}

TEST(ReferenceConsistency, WithThreeGyrosARampStaysCoveredAfterItsDetection) {
  // Three gyros, a ramp of 1e-6 or 2e-6 deg/s² on each gyro in turn from 60 s, two seeds, 600 s: detected by
  // the reference's tests 71–111 s after onset, then the rate error keeps growing. Before, the bias states
  // opened once by |z|/window and sigma fell short as the ramp grew (90.3–97.2 % within 3σ after the
  // detection in these runs); the noise matched along the gyro's rate axis now keeps it over the ramp
  // (98.4–100 %). Criterion: the campaign's 97 % within 3σ from the detection on.
  for (const double size : {1e-6, 2e-6}) {
    for (const int gyro : {1, 2, 3}) {
      for (const std::uint64_t seed : {1u, 2u}) {
        const Outcome o = run(three_gyros_with(sim::FaultKind::kRamp, gyro, size, 600.0), seed);
        ASSERT_GE(o.first_detected_s, 60.0) << summary(o);
        EXPECT_GE(fraction(o.within_after, o.total_after), 0.97)
            << size << " gyro " << gyro << " seed " << seed << ": " << summary(o);
      }
    }
  }
}

TEST(ProtectionLevel, SlowRampBelowTheThresholdStaysWithinIt) {
  // 3e-7 deg/s² from 60 s, no reference, 30 min: the CUSUM sees it after 210..285 s (its rate then ≈ 7e-5
  // deg/s, below the CUSUM's k); the error stays within the protection level on every axis at every sampled
  // epoch, before and after (|e|/PL ≤ 0.25 measured). The level is finite (parity) and grows without a
  // reference.
  auto sc = sim::builtin_scenario("orbit");
  ASSERT_TRUE(sc.ok());
  sc->duration_s = 1860.0;
  sc->reference = sim::ReferenceOptions{};
  for (int gyro : {1, 2, 4}) {
    sim::FaultSpec f;
    f.gyro = gyro;
    f.kind = sim::FaultKind::kRamp;
    f.at_s = 60.0;
    f.size = 3e-7;
    sc->faults = {f};
    const Outcome o = run(*sc, 7);
    EXPECT_GT(o.first_detected_s, 200.0) << gyro;  // below the threshold for minutes
    EXPECT_EQ(o.beyond_protection, 0) << gyro << ": worst |e|/PL " << o.worst_protection_ratio;
    EXPECT_LT(o.worst_protection_ratio, 1.0) << gyro;
  }
}

}  // namespace
}  // namespace tetra
