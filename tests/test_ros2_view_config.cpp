// The `ros2:` map of the fusion service's configuration (docs/ros2.md): ROS 2 names, defaults, errors.

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/service/fusion_config.hpp"
#include "tetra/service/ros2_view_config.hpp"

namespace tetra::service {
namespace {

TEST(Ros2ViewConfig, UnitNamesBecomeRosNameTokens) {
  EXPECT_EQ(ros2_name("tetra-1"), "tetra_1");
  EXPECT_EQ(ros2_name("lab unit.2"), "lab_unit_2");
  EXPECT_EQ(ros2_name("a--b"), "a_b");  // ROS 2 forbids "__"
  EXPECT_EQ(ros2_name("7x"), "unit_7x");
  EXPECT_EQ(ros2_name("x-"), "x");
  for (const char* unit : {"tetra-1", "lab unit.2", "a--b", "7x", "x-", "-", ""}) {
    EXPECT_TRUE(is_ros2_name(ros2_name(unit))) << unit << " -> " << ros2_name(unit);
  }
  EXPECT_FALSE(is_ros2_name("a__b"));
  EXPECT_FALSE(is_ros2_name("1a"));
  EXPECT_FALSE(is_ros2_name("a-b"));
}

class Ros2ViewConfigFile : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(write_calibration(dir.file("cal.yaml"), seed_as_built_unit()).ok()); }
  Result<FusionConfig> parse(const std::string& text) {
    return parse_fusion_config("calibration: cal.yaml\nunit: tetra-1\n" + text, "f.yaml",
                               dir.path().string());
  }
  test::TempDir dir;
};

TEST_F(Ros2ViewConfigFile, OffByDefaultAndDefaultsFromTheUnit) {
  auto off = parse("");
  ASSERT_TRUE(off.ok()) << off.error().message;
  EXPECT_FALSE(off->ros2.enabled);
  EXPECT_NE(describe(*off).find("ros2: off"), std::string::npos);

  auto on = parse("ros2:\n  enabled: true\n");
  ASSERT_TRUE(on.ok()) << on.error().message;
  EXPECT_TRUE(on->ros2.enabled);
  const Ros2ViewConfig r = on->ros2.resolved(on->unit);
  EXPECT_EQ(r.name, "tetra_1");
  EXPECT_EQ(r.frame_id, "tetra_1_body");
  EXPECT_EQ(r.reference_frame_id, "tetra_1_reference");
  EXPECT_NE(describe(*on).find("ros2: rt/tetra/tetra_1/{attitude,imu}, rt/diagnostics"), std::string::npos);

  auto named = parse("ros2: {enabled: true, name: imu_a, frame_id: imu_link, reference_frame_id: map}\n");
  ASSERT_TRUE(named.ok()) << named.error().message;
  const Ros2ViewConfig n = named->ros2.resolved(named->unit);
  EXPECT_EQ(n.name, "imu_a");
  EXPECT_EQ(n.frame_id, "imu_link");
  EXPECT_EQ(n.reference_frame_id, "map");
}

TEST_F(Ros2ViewConfigFile, ErrorsNameTheLineAndTheKey) {
  auto bad_name = parse("ros2:\n  enabled: true\n  name: tetra-1\n");
  ASSERT_FALSE(bad_name.ok());
  EXPECT_NE(bad_name.error().message.find("f.yaml:5"), std::string::npos) << bad_name.error().message;
  EXPECT_NE(bad_name.error().message.find("ros2.name 'tetra-1' is not a ROS 2 name"), std::string::npos)
      << bad_name.error().message;
  auto unknown = parse("ros2:\n  topic: x\n");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("f.yaml:4"), std::string::npos) << unknown.error().message;
  auto flag = parse("ros2:\n  enabled: yes please\n");
  ASSERT_FALSE(flag.ok());
  EXPECT_NE(flag.error().message.find("ros2.enabled must be true or false"), std::string::npos);
  EXPECT_FALSE(parse("ros2: true\n").ok());
}

}  // namespace
}  // namespace tetra::service
