// Detector statistics, configuration parsing and event formatting.
#include <cmath>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "tetra/fdi/budget.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/detectors.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi {
namespace {

TEST(Chi2, SurvivalMatchesKnownQuantiles) {
  // Textbook quantiles (4 significant digits): χ²_1(0.95) = 3.841, χ²_2(0.99) = 9.210, χ²_3(0.95) = 7.815,
  // χ²_4(0.999) = 18.47; the survival function must give back 0.05, 0.01, 0.05, 0.001 to that precision.
  EXPECT_NEAR(chi2_survival(3.841459, 1), 0.05, 1e-6);
  EXPECT_NEAR(chi2_survival(9.210340, 2), 0.01, 1e-6);
  EXPECT_NEAR(chi2_survival(7.814728, 3), 0.05, 1e-6);
  EXPECT_NEAR(chi2_survival(18.46683, 4), 0.001, 1e-6);
}

TEST(Chi2, ThresholdInvertsSurvival) {
  // For d = 1 the 1e-9 threshold is z² with z = 6.1094 (two-sided normal tail 1e-9).
  EXPECT_NEAR(chi2_threshold(1e-9, 1), 6.109410204 * 6.109410204, 1e-6);
  for (int d = 1; d <= 6; ++d) {
    for (double p : {1e-2, 1e-6, 1e-9}) {
      const double x = chi2_threshold(p, d);
      EXPECT_NEAR(chi2_survival(x, d) / p, 1.0, 1e-8) << "d=" << d << " p=" << p;
    }
  }
}

TEST(Cusum, SiegmundArlMatchesTabulatedValues) {
  // One-sided CUSUM k = 0.5, h = 4: in-control ARL ≈ 336 and ARL at a 1σ shift ≈ 8.4 (Montgomery's
  // table, from the same approximation); checked to 1 %.
  EXPECT_NEAR(cusum_arl(0.0, 0.5, 4.0), 336.0, 3.4);
  EXPECT_NEAR(cusum_arl(1.0, 0.5, 4.0), 8.38, 0.09);
  // The two-sided threshold gives back the requested ARL0 (two branches: ARL(−k)/2).
  const double h = cusum_threshold(0.44, 1e8);
  EXPECT_NEAR(cusum_arl(0.0, 0.44, h) / 2.0 / 1e8, 1.0, 1e-6);
}

TEST(Config, DefaultsValidateAndDescribeEveryKey) {
  const PipelineConfig c;
  EXPECT_TRUE(validate(c).ok());
  const std::string d = describe(c);
  for (const char* key :
       {"latitude_deg", "false_alarm_probability", "reference_window_s", "noise_high_ratio"}) {
    EXPECT_NE(d.find(key), std::string::npos) << key;
  }
}

TEST(Config, ParsesKeysAndRejectsUnknownOnesWithLine) {
  const auto root = YAML::Load(
      "pipeline:\n  latitude_deg: -23.2\n  false_alarm_probability: 1e-8\n  raw_units_dps: true\n");
  auto c = pipeline_config_from_yaml(root["pipeline"], "cfg.yaml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_DOUBLE_EQ(*c->latitude_deg, -23.2);
  EXPECT_DOUBLE_EQ(c->false_alarm_probability, 1e-8);
  EXPECT_DOUBLE_EQ(cusum_arl0_epochs(*c), 1e7);  // the CUSUM's share: 10
  EXPECT_TRUE(c->raw_units_dps);

  const auto bad = YAML::Load("pipeline:\n  latitude_deg: 1\n  false_alarm_probabilty: 5\n");
  auto e = pipeline_config_from_yaml(bad["pipeline"], "cfg.yaml");
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("cfg.yaml:3:"), std::string::npos) << e.error().message;
  EXPECT_NE(e.error().message.find("false_alarm_probabilty"), std::string::npos);

  const auto range = YAML::Load("pipeline:\n  false_alarm_probability: 0.001\n");
  auto r = pipeline_config_from_yaml(range["pipeline"], "cfg.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("false_alarm_probability"), std::string::npos);

  const auto text = YAML::Load("pipeline:\n  onset_sigma: abc\n");
  EXPECT_FALSE(pipeline_config_from_yaml(text["pipeline"], "cfg.yaml").ok());
}

TEST(Events, JsonLinesFollowTheContract) {
  FdiEvent d;
  d.stamp_ns = 1'800'400'000'000;
  d.type = EventType::kDetected;
  EXPECT_EQ(detection_test_from_string(to_string(DetectionTest::kLevel)), DetectionTest::kLevel);
  EXPECT_STREQ(to_string(DetectionTest::kLevel), "level");
  d.test = DetectionTest::kCusum;
  d.statistic = 14.25;
  EXPECT_EQ(to_json(d, 4),
            R"({"time_s": 1800.4, "event": "detected", "gyro": null, "test": "cusum", "statistic": 14.25})");
  FdiEvent i;
  i.stamp_ns = 1'801'000'000'000;
  i.type = EventType::kIsolated;
  i.gyro = 2;
  i.kind = FaultKind::kStuck;
  i.evidence = Evidence::kVariance;
  EXPECT_EQ(to_json(i, 4),
            R"({"time_s": 1801, "event": "isolated", "gyro": 2, "kind": "stuck", "evidence": "variance"})");
  FdiEvent r;
  r.stamp_ns = 1'801'000'000'000;
  r.type = EventType::kReconfigured;
  r.gyros = 0b1101;
  EXPECT_EQ(to_json(r, 4), R"({"time_s": 1801, "event": "reconfigured", "gyros": [1, 3, 4]})");
  for (int k = 0; k <= static_cast<int>(FaultKind::kUnknown); ++k) {
    const auto kind = static_cast<FaultKind>(k);
    EXPECT_EQ(fault_kind_from_string(to_string(kind)), kind);
  }
}

}  // namespace
}  // namespace tetra::fdi
