// Dispersed campaigns (tetra/sim/dispersion.hpp): draws as a pure function of (seed, run), their laws,
// their application to the run's truth (never to the pipeline's calibration), and spec errors naming
// the file, line and key.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/campaign_statistics.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::sim {
namespace {

using test::TempDir;

std::string spec_head(int seeds = 4) {
  return "scenarios: [" + test::source_path("examples/sim/closed_loop_calibrated.yaml") +
         "]\nduration_s: 600\nkinds: [bias, stuck]\nsizes: {bias: [0.002]}\ngyros: [1, 2]\n"
         "onsets_s: [100]\nseeds: {first: 1, count: " +
         std::to_string(seeds) + "}\nfault_free: true\n";
}

Result<CampaignSpec> spec_from(const TempDir& dir, const std::string& text) {
  test::write_file(dir.file("spec.yaml"), text);
  return read_campaign_spec(dir.file("spec.yaml"));
}

TEST(CampaignDispersion, DrawsArePureFunctionsOfSeedAndRunAndAppliedToTheTruthOnly) {
  TempDir dir;
  const auto spec = spec_from(dir, spec_head() +
                                       "dispersions:\n  seed: 7\n  unit.scale_factor_ppm: calibration\n"
                                       "  unit.axis: {calibration: 2}\n  fault.onset_s: {uniform: [0, 400]}\n"
                                       "  fault.size_factor: {log_uniform: [0.1, 10]}\n");
  ASSERT_TRUE(spec) << spec.error().message;
  ASSERT_EQ(campaign_run_count(*spec).value(), 4u + 2u * 2u * 4u);
  const CampaignCase a = campaign_case(*spec, 9);
  const CampaignCase again = campaign_case(*spec, 9);
  EXPECT_EQ(a.draws, again.draws);                     // the same run, the same draws, bit for bit
  EXPECT_NE(a.draws, campaign_case(*spec, 10).draws);  // another run, others
  ASSERT_EQ(a.draws.size(), 4u);
  EXPECT_EQ(a.draws[0].size(), 4u);   // per gyro
  EXPECT_EQ(a.draws[1].size(), 12u);  // per gyro and component
  // The fault as drawn: onset 100 + [0, 400), size 0.002 × [0.1, 10].
  ASSERT_TRUE(a.fault);
  EXPECT_EQ(a.fault->at_s, 100.0 + a.draws[2][0]);
  EXPECT_GE(a.fault->at_s, 100.0);
  EXPECT_LT(a.fault->at_s, 500.0);
  EXPECT_EQ(a.fault->size, 0.002 * a.draws[3][0]);
  // The truth is dispersed; the spec's scenario (the pipeline's calibration) is not.
  const Scenario truth = campaign_scenario(*spec, a);
  const Calibration& nominal = spec->scenarios[0].unit;
  for (std::size_t g = 0; g < 4; ++g) {
    EXPECT_DOUBLE_EQ(truth.unit.gyros[g].scale_factor_V_per_dps,
                     nominal.gyros[g].scale_factor_V_per_dps * (1.0 + a.draws[0][g] * 1e-6));
    EXPECT_NEAR(truth.unit.gyros[g].axis_B.norm(), 1.0, 1e-15);  // renormalized (1e-15: rounding)
    EXPECT_NE(truth.unit.gyros[g].axis_B, nominal.gyros[g].axis_B);
  }
  // Adding a parameter leaves the others' draws unchanged (one engine per parameter).
  const auto more = spec_from(dir, spec_head() +
                                       "dispersions:\n  seed: 7\n  unit.bias_V: {normal: [0, 1e-6]}\n"
                                       "  unit.scale_factor_ppm: calibration\n  unit.axis: {calibration: 2}\n"
                                       "  fault.onset_s: {uniform: [0, 400]}\n"
                                       "  fault.size_factor: {log_uniform: [0.1, 10]}\n");
  ASSERT_TRUE(more) << more.error().message;
  EXPECT_EQ(campaign_case(*more, 9).draws[1], a.draws[0]);
  // The row carries the draws in appended columns; the header names them.
  const std::string header = campaign_csv_header(*spec);
  EXPECT_EQ(header.rfind(campaign_csv_header(), 0), 0u);  // the columns of before, in their order, first
  EXPECT_NE(header.find(",unit.scale_factor_ppm.g1,"), std::string::npos) << header;
  EXPECT_NE(header.find(",unit.axis.g4.z,fault.onset_s,fault.size_factor"), std::string::npos) << header;
}

TEST(CampaignDispersion, LawsAndTheCalibrationSigma) {
  TempDir dir;
  const auto spec = spec_from(dir, spec_head() +
                                       "dispersions:\n  seed: 3\n  unit.scale_factor_ppm: calibration\n"
                                       "  unit.arw_factor: {truncated_normal: [1, 0.5, 0.8, 1.1]}\n"
                                       "  reference.noise_arcsec: {uniform: [3, 10]}\n"
                                       "  fault.gyro: {choice: [2]}\n");
  ASSERT_TRUE(spec) << spec.error().message;
  const Calibration& unit = spec->scenarios[0].unit;
  const double sigma_ppm =
      unit.gyros[0].sigma->scale_factor_V_per_dps / unit.gyros[0].scale_factor_V_per_dps * 1e6;
  constexpr int kRuns = 4000;
  double sum2 = 0.0;
  double arw_sum = 0.0;
  for (int run = 0; run < kRuns; ++run) {
    const DispersionDraws d = draw_dispersions(spec->dispersions, static_cast<std::uint64_t>(run), unit);
    sum2 += d[0][0] * d[0][0];
    for (double f : d[1]) {
      ASSERT_GE(f, 0.8);
      ASSERT_LE(f, 1.1);
      arw_sum += f;
    }
    ASSERT_GE(d[2][0], 3.0);
    ASSERT_LT(d[2][0], 10.0);
    ASSERT_EQ(d[3][0], 2.0);
  }
  // The standard deviation of 4000 normal draws is within 2.2 % (1σ) of σ: 10 % is 4.5σ.
  EXPECT_NEAR(std::sqrt(sum2 / kRuns), sigma_ppm, 0.1 * sigma_ppm);
  // Mean of N(1, 0.5) truncated to [0.8, 1.1]: 0.9515 (from the closed form μ + σ(φ(α) − φ(β))/(Φ(β) −
  // Φ(α))); the draws' standard deviation is 0.0861, so 16000 of them average within 6.8e-4 (1σ): 3e-3
  // is 4.4σ.
  EXPECT_NEAR(arw_sum / (4.0 * kRuns), 0.9515, 3e-3);
}

TEST(CampaignDispersion, AWarmUpAndARateRampAreDrawnIntoTheTruthOnly) {
  // Beyond the stated envelope as the campaign draws it: each gyro's thermal coefficient c_i, the unit's
  // temperature at the start (settling at the scenario's 20 °C, where it was calibrated), and a rate ramp R
  // the calibration does not state.
  TempDir dir;
  const auto spec = spec_from(dir, spec_head() +
                                       "dispersions:\n  seed: 5\n"
                                       "  thermal.bias_dps_per_K: {uniform: [-2.0e-6, 2.0e-6]}\n"
                                       "  thermal.start_C: {uniform: [-5, 10]}\n"
                                       "  unit.rate_ramp_dps2: {log_uniform: [1.0e-10, 1.0e-8]}\n");
  ASSERT_TRUE(spec) << spec.error().message;
  const CampaignCase a = campaign_case(*spec, 3);
  ASSERT_EQ(a.draws.size(), 3u);
  ASSERT_EQ(a.draws[0].size(), 4u);
  ASSERT_EQ(a.draws[2].size(), 4u);
  const Scenario truth = campaign_scenario(*spec, a);
  EXPECT_EQ(truth.thermal.bias_dps_per_K, a.draws[0]);
  EXPECT_EQ(truth.thermal.start_C, a.draws[1][0]);
  EXPECT_GE(truth.thermal.start_C, -5.0);
  EXPECT_LT(truth.thermal.start_C, 10.0);
  // At t = 0 gyro 1's thermal bias is c_1·(T_start − 20 °C): 10–25 K below, up to 5e-5 deg/s.
  EXPECT_DOUBLE_EQ(truth.thermal.bias_dps(0, 0.0), a.draws[0][0] * (a.draws[1][0] - 20.0));
  const Calibration& nominal = spec->scenarios[0].unit;
  for (std::size_t g = 0; g < 4; ++g) {
    ASSERT_TRUE(truth.unit.gyros[g].noise);
    EXPECT_EQ(truth.unit.gyros[g].noise->rate_ramp_dps_per_s, a.draws[2][g]);
    EXPECT_GE(a.draws[2][g], 1e-10);
    EXPECT_LT(a.draws[2][g], 1e-8);
    // The pipeline's calibration (the spec's scenario) states neither.
    EXPECT_FALSE(nominal.gyros[g].noise && nominal.gyros[g].noise->rate_ramp_dps_per_s);
  }
  EXPECT_FALSE(spec->scenarios[0].thermal.active());
  // The example campaign beyond the envelope draws them for its five-gyro unit.
  const auto example = read_campaign_spec(test::source_path("examples/campaign_beyond_envelope.yaml"));
  ASSERT_TRUE(example) << example.error().message;
  ASSERT_EQ(example->scenarios[0].unit.gyro_count(), 5);
  const Scenario warm = campaign_scenario(*example, campaign_case(*example, 0));
  EXPECT_EQ(warm.thermal.bias_dps_per_K.size(), 5u);
  EXPECT_LE(warm.thermal.start_C, 10.0);
  const std::string header = campaign_csv_header(*spec);
  EXPECT_NE(header.find(",thermal.bias_dps_per_K.g1,"), std::string::npos) << header;
  EXPECT_NE(header.find(",thermal.start_C,unit.rate_ramp_dps2.g1,"), std::string::npos) << header;
  // What a warm-up's supports cannot give is refused before any run, naming the key.
  struct Case {
    std::string tail;
    std::string text;
  };
  const std::vector<Case> cases = {
      {"  thermal.bias_dps_per_K: {normal: [0, 1.0e-6]}\n  thermal.start_C: {uniform: [0, 5]}\n", "bounded"},
      {"  thermal.bias_dps_per_K: {uniform: [-0.1, 0.1]}\n  thermal.start_C: {uniform: [0, 5]}\n",
       "is a bias above 1 deg/s"},
      {"  thermal.bias_dps_per_K: {uniform: [0, 1.0e-6]}\n  thermal.start_C: {uniform: [0, 500]}\n",
       "thermal.start_C"},
      {"  thermal.start_C: {uniform: [0, 5]}\n", "needs its coefficients"},
      {"  thermal.bias_dps_per_K: {uniform: [0, 1.0e-6]}\n", "no warm-up to give"},
      {"  unit.rate_ramp_dps2: {uniform: [-1.0e-9, 1.0e-9]}\n", "R is a magnitude"},
  };
  for (const Case& c : cases) {
    const auto bad = spec_from(dir, spec_head() + "dispersions:\n  seed: 1\n" + c.tail);
    ASSERT_FALSE(bad) << c.tail;
    EXPECT_NE(bad.error().message.find("spec.yaml:11"), std::string::npos) << bad.error().message;
    EXPECT_NE(bad.error().message.find(c.text), std::string::npos) << bad.error().message;
  }
}

TEST(CampaignDispersion, SpecErrorsNameTheLineAndKey) {
  TempDir dir;
  struct Case {
    std::string tail;
    std::string line;
    std::string text;
  };
  const std::vector<Case> cases = {
      {"dispersions:\n  seed: 1\n  unit.wobble: {normal: [0, 1]}\n", "spec.yaml:11",
       "dispersions.unit.wobble"},
      {"dispersions:\n  unit.bias_V: {normal: [0, 1]}\n", "spec.yaml:10", "dispersions.seed"},
      {"dispersions:\n  seed: 1\n  fault.onset_s: {normal: [0, 1]}\n", "spec.yaml:11", "bounded"},
      {"dispersions:\n  seed: 1\n  fault.onset_s: {uniform: [0, 600]}\n", "spec.yaml:11",
       "do not all lie in"},
      {"dispersions:\n  seed: 1\n  unit.arw_factor: {normal: [1, 0.1]}\n", "spec.yaml:11",
       "must not be negative"},
      {"dispersions:\n  seed: 1\n  fault.gyro: {choice: [3]}\n", "spec.yaml:11", "not in gyros"},
      {"dispersions:\n  seed: 1\n  unit.arw_factor: calibration\n", "spec.yaml:11", "no calibration"},
      {"dispersions:\n  seed: 1\n  data.jitter_s: {uniform: [0, 0.01]}\n", "spec.yaml:11", "open-loop"},
      {"dispersions:\n  seed: 1\n  unit.bias_V: {uniform: [2, 1]}\n", "spec.yaml:11",
       "min must be below max"},
      {"requirements: [wrong_exclusion_rate < 2 at 0.95]\n", "spec.yaml:9", "requirements[0]"},
      {"requirements: ['detection_rate[ramp] > 0.9 at 0.95']\n", "spec.yaml:9", "runs no ramp"},
      {"requirements: ['false_alarms_per_hour < 0.1 at 95']\n", "spec.yaml:9", "confidence"},
      {"requirements: ['false_alarms_per_hour < 0x1p-3 at 0.95']\n", "spec.yaml:9", "bound '0x1p-3'"},
  };
  for (const Case& c : cases) {
    const auto spec = spec_from(dir, spec_head() + c.tail);
    ASSERT_FALSE(spec) << c.tail;
    EXPECT_NE(spec.error().message.find(c.line), std::string::npos) << spec.error().message;
    EXPECT_NE(spec.error().message.find(c.text), std::string::npos) << spec.error().message;
  }
  // Open loop at the orbit's 10 Hz: a jitter reaching half the period (0.05 s) made every run an error row.
  test::write_file(dir.file("jitter.yaml"),
                   "loop: open\nscenarios: [orbit]\nkinds: [stuck]\ngyros: [1]\nonsets_s: [100]\nseeds: [1]\n"
                   "dispersions: {seed: 1, data.jitter_s: {uniform: [0, 0.2]}}\n");
  const auto jitter = read_campaign_spec(dir.file("jitter.yaml"));
  ASSERT_FALSE(jitter);
  EXPECT_NE(jitter.error().message.find("reaches half the sampling period (0.05 s)"), std::string::npos)
      << jitter.error().message;
  // The seed's unit states no 1σ: `calibration` is refused naming the gyro.
  test::write_file(dir.file("nadir.yaml"), "scenarios: [" +
                                               test::source_path("examples/sim/closed_loop_nadir.yaml") +
                                               "]\nkinds: [stuck]\ngyros: [1]\nonsets_s: [100]\nseeds: [1]\n"
                                               "dispersions: {seed: 1, unit.axis: calibration}\n");
  const auto nadir = read_campaign_spec(dir.file("nadir.yaml"));
  ASSERT_FALSE(nadir);
  EXPECT_NE(nadir.error().message.find("gyro 1 of scenarios[0]"), std::string::npos) << nadir.error().message;
}

TEST(CampaignDispersion, RequirementsJudged) {
  std::vector<CampaignRow> rows(3000);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].run = i;
    rows[i].kind = i < 1000 ? "none" : "bias";
    rows[i].gyro = 1;
    rows[i].fdi.outcome = i < 1000 ? Outcome::kNone : Outcome::kRight;
    if (i >= 1000) rows[i].fdi.detection_delay_s = 1.0;
    rows[i].fdi.fault_free_s = 3600.0;
  }
  const auto judge = [&](const std::string& text) {
    auto q = parse_requirement(text);
    EXPECT_TRUE(q) << text;
    return judge_requirement(*q, rows);
  };
  // 0 of 3000: the 95 % upper bound 1 − 0.05^(1/3000) = 9.98e-4 < 1e-3: pass.
  EXPECT_EQ(judge("wrong_exclusion_rate < 1e-3 at 0.95").verdict, Verdict::kPass);
  // At 0.99 it is not yet decidable: 0 events need n with 0.01^(1/n) ≥ 0.999, n ≥ 4603: 1603 more.
  const RequirementJudgement strict = judge("wrong_exclusion_rate < 1e-3 at 0.99");
  EXPECT_EQ(strict.verdict, Verdict::kUndecided);
  EXPECT_EQ(strict.further_runs, 1603u);
  EXPECT_EQ(judge("detection_rate[bias] > 0.99 at 0.95").verdict, Verdict::kPass);
  EXPECT_EQ(judge("missed_rate > 0.01 at 0.95").verdict, Verdict::kFail);
  // No false alarm in 3000 h: the upper bound −ln(0.05)/3000 h = 1.0e-3 per hour.
  EXPECT_EQ(judge("false_alarms_per_hour < 1.1e-3 at 0.95").verdict, Verdict::kPass);
  const RequirementJudgement fa = judge("false_alarms_per_hour < 1e-4 at 0.95");
  EXPECT_EQ(fa.verdict, Verdict::kUndecided);
  // 29957 h are needed (2.9957/1e-4) at 1 h a run: 26958 more runs.
  EXPECT_EQ(fa.further_runs, 26958u);
}

}  // namespace
}  // namespace tetra::sim

namespace tetra::sim {
namespace {

// Star-tracker dropouts (reference.drop_probability): each sample left out independently, from a stream
// of its own, so the samples delivered are exactly those of the run without dropouts.
TEST(ReferenceDropouts, DeliveredSamplesAreThoseOfTheRunWithoutDropouts) {
  const std::string base =
      "scenario: orbit\nduration_s: 200\nrate_hz: 10\nreference: {rate_hz: 1, noise_arcsec: 5";
  auto full = parse_scenario(base + "}\n", "full.yaml");
  auto dropping = parse_scenario(base + ", drop_probability: 0.5}\n", "drop.yaml");
  ASSERT_TRUE(full && dropping) << (full ? dropping.error().message : full.error().message);
  auto a = Simulator::create(*full, SimOptions{});
  auto b = Simulator::create(*dropping, SimOptions{});
  ASSERT_TRUE(a && b);
  SimEpoch ea;
  SimEpoch eb;
  int references = 0;
  int delivered = 0;
  while (a->next(ea) && b->next(eb)) {
    if (!ea.reference_q_RB) {
      EXPECT_FALSE(eb.reference_q_RB);
      continue;
    }
    ++references;
    if (!eb.reference_q_RB) continue;
    ++delivered;
    EXPECT_EQ(ea.reference_q_RB->coeffs(), eb.reference_q_RB->coeffs());
  }
  EXPECT_EQ(references, 200);
  // Binomial(200, 0.5): 1σ = 7.1; 100 ± 30 is 4.2σ.
  EXPECT_NEAR(delivered, 100, 30);
  const auto bad = parse_scenario(base + ", drop_probability: 1}\n", "bad.yaml");
  EXPECT_TRUE(!bad || !validate_scenario(*bad)) << "a probability of 1 is refused";
}

}  // namespace
}  // namespace tetra::sim
