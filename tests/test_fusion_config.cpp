// Configuration of `tetra fusion` (services/fusion/fusion_config.hpp): defaults, errors that name
// the file, line and key, calibration paths relative to the configuration file.

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/service/fusion_config.hpp"

namespace tetra::service {
namespace {

class FusionConfigTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(write_calibration(dir.file("cal.yaml"), seed_as_built_unit()).ok()); }
  Result<FusionConfig> parse(const std::string& text) {
    return parse_fusion_config(text, "f.yaml", dir.path().string());
  }
  test::TempDir dir;
};

TEST_F(FusionConfigTest, MinimalFileTakesTheDefaults) {
  auto config = parse("calibration: cal.yaml\n");
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->unit, "tetra-1");
  EXPECT_EQ(config->calibration.gyro_count(), 4);
  EXPECT_EQ(config->calibration_path, dir.file("cal.yaml"));  // resolved against the file's folder
  // 100 Hz: deadline 3 periods = 30 ms exactly (integer ns).
  EXPECT_EQ(config->deadline_ns(), 30'000'000);
  const auto assembler = config->assembler(4);
  EXPECT_EQ(assembler.nominal_period_ns, 10'000'000);
  EXPECT_EQ(assembler.tolerance_ns, 2'500'000);  // a quarter period by default
  EXPECT_EQ(assembler.max_latency_ns, 20'000'000);
  EXPECT_EQ(config->gyro_dispatch, service::GyroDispatch::kListener);
}

TEST_F(FusionConfigTest, GyroDispatchIsListenerOrWaitset) {
  auto waitset = parse("calibration: cal.yaml\ngyro_dispatch: waitset\n");
  ASSERT_TRUE(waitset.ok()) << waitset.error().message;
  EXPECT_EQ(waitset->gyro_dispatch, service::GyroDispatch::kWaitset);
  EXPECT_NE(service::describe(*waitset).find("gyro_dispatch: waitset"), std::string::npos);
  auto bad = parse("calibration: cal.yaml\ngyro_dispatch: polling\n");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("f.yaml:2:"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("gyro_dispatch"), std::string::npos) << bad.error().message;
}

TEST_F(FusionConfigTest, SpeedShortensTheWallClockDeadline) {
  auto config = parse("calibration: cal.yaml\nsample_rate_hz: 50\nspeed: 4\n");
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->deadline_ns(), 15'000'000);                   // 3 / (50 Hz · 4)
  EXPECT_EQ(config->assembler(4).nominal_period_ns, 20'000'000);  // sensor time is not scaled
}

TEST_F(FusionConfigTest, UnknownKeyIsAnErrorNamingTheLine) {
  auto config = parse("calibration: cal.yaml\nsample_rate: 100\n");
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.error().message.find("f.yaml:2:"), std::string::npos) << config.error().message;
  EXPECT_NE(config.error().message.find("sample_rate"), std::string::npos);
}

TEST_F(FusionConfigTest, BadValuesAreRejectedByName) {
  for (const char* text :
       {"calibration: cal.yaml\nsample_rate_hz: -1\n", "calibration: cal.yaml\nspeed: 0\n",
        "calibration: cal.yaml\nhealth_period_s: 2\n", "calibration: cal.yaml\ntolerance_s: 0.005\n",
        "calibration: cal.yaml\nunit: a-name-that-is-far-too-long-for-the-wire-0123\n",
        "calibration: cal.yaml\nmax_latency_s: abc\n", "unit: u\n"}) {
    auto config = parse(text);
    EXPECT_FALSE(config.ok()) << text;
    if (!config.ok()) {
      EXPECT_EQ(config.error().kind, ErrorKind::kBadInput) << text;
    }
  }
  auto missing = parse("calibration: nowhere.yaml\n");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("nowhere.yaml"), std::string::npos);
}

TEST_F(FusionConfigTest, UnitNameWithANewlineOrInvalidUtf8IsRefusedNamingTheKey) {
  const std::pair<const char*, const char*> cases[] = {
      {"calibration: cal.yaml\nunit: \"tetra\\n1\"\n", "control character"},
      {"calibration: cal.yaml\nunit: \"a\\tb\"\n", "control character"},
      {"calibration: cal.yaml\nunit: \"bad\xff\"\n", "not valid UTF-8"},
      {"calibration: cal.yaml\nunit: \"\"\n", "1 to 31 bytes"}};
  for (const auto& [text, why] : cases) {
    auto config = parse(text);
    ASSERT_FALSE(config.ok()) << text;
    EXPECT_EQ(config.error().kind, ErrorKind::kBadInput);
    EXPECT_NE(config.error().message.find("f.yaml:2: unit"), std::string::npos) << config.error().message;
    EXPECT_NE(config.error().message.find(why), std::string::npos) << config.error().message;
  }
  EXPECT_TRUE(parse("calibration: cal.yaml\nunit: \"Einheit-α\"\n").ok());  // UTF-8 text is fine
}

TEST_F(FusionConfigTest, ClockWindowDefaultsAndBounds) {
  auto config = parse("calibration: cal.yaml\n");
  ASSERT_TRUE(config.ok());
  EXPECT_EQ(config->assembler(4).clock_window_ns, 100'000'000);  // 0.1 s at 100 Hz
  EXPECT_EQ(config->assembler(4).speed, 1.0);
  auto slow = parse("calibration: cal.yaml\nsample_rate_hz: 10\n");
  ASSERT_TRUE(slow.ok());
  EXPECT_EQ(slow->assembler(4).clock_window_ns, 400'000'000);  // 4 periods at 10 Hz
  auto set = parse("calibration: cal.yaml\nclock_window_s: 0.5\n");
  ASSERT_TRUE(set.ok());
  EXPECT_EQ(set->assembler(4).clock_window_ns, 500'000'000);
  for (const char* text :
       {"calibration: cal.yaml\nclock_window_s: 0.01\n", "calibration: cal.yaml\nclock_window_s: 1e300\n",
        "calibration: cal.yaml\nmax_latency_s: 1e300\n", "calibration: cal.yaml\ntolerance_s: -1e300\n"}) {
    auto bad = parse(text);
    ASSERT_FALSE(bad.ok()) << text;
    EXPECT_EQ(bad.error().kind, ErrorKind::kBadInput);
  }
}

TEST_F(FusionConfigTest, PipelineMapIsThePipelinesOwn) {
  auto config = parse("calibration: cal.yaml\npipeline:\n  initial_q_wxyz: [0, 1, 0, 0]\n");
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->pipeline.initial_q_RB.x(), 1.0);
  EXPECT_FALSE(parse("calibration: cal.yaml\npipeline:\n  no_such_setting: 1\n").ok());
}

}  // namespace
}  // namespace tetra::service
