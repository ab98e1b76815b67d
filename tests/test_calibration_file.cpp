// Calibration YAML (docs/interfaces.md §2.3): round trip, unknown keys and bad values rejected with line
// numbers.
#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"

namespace tetra {
namespace {

TEST(CalibrationFile, RoundTripIsExact) {
  Calibration cal = seed_as_built_unit();
  cal.gyros[1].sigma = GyroSigma{1.2e-6, 3e-7, Eigen::Vector3d(2e-6, 3e-6, 4e-6)};
  test::TempDir dir;
  ASSERT_TRUE(write_calibration(dir.file("c.yaml"), cal).ok());
  const auto back = read_calibration(dir.file("c.yaml"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->gyro_count(), 4);
  for (int i = 0; i < 4; ++i) {
    const auto& a = cal.gyros[static_cast<std::size_t>(i)];
    const auto& b = back->gyros[static_cast<std::size_t>(i)];
    EXPECT_EQ(a.scale_factor_V_per_dps, b.scale_factor_V_per_dps);
    EXPECT_EQ(a.bias_V, b.bias_V);
    EXPECT_EQ(a.axis_B, b.axis_B);
    EXPECT_EQ(a.noise->arw_dps_rtHz, b.noise->arw_dps_rtHz);
  }
  EXPECT_EQ(back->gyros[1].sigma->axis.z(), 4e-6);
  EXPECT_EQ(back->latitude_deg.value(), -23.2);
}

TEST(CalibrationFile, ExampleFactoryFileLoads) {
  const auto cal = read_calibration(test::source_path("examples/factory.yaml"));
  ASSERT_TRUE(cal.ok()) << cal.error().message;
  EXPECT_EQ(cal->gyro_count(), 4);
  EXPECT_EQ(cal->gyros[3].scale_factor_V_per_dps, 0.0518);  // seed Table 2
}

std::string three_gyros(const std::string& extra_in_first) {
  return "unit: u\ngyros:\n"
         "  - id: 1\n    scale_factor_V_per_dps: 0.07\n    bias_V: 0\n    axis: [1, 0, 0]\n" +
         extra_in_first +
         "  - id: 2\n    scale_factor_V_per_dps: 0.07\n    bias_V: 0\n    axis: [0, 1, 0]\n"
         "  - id: 3\n    scale_factor_V_per_dps: 0.07\n    bias_V: 0\n    axis: [0, 0, 1]\n";
}

TEST(CalibrationFile, UnknownKeyNamesLineAndKey) {
  ASSERT_TRUE(parse_calibration(three_gyros(""), "ok.yaml").ok());
  const auto r = parse_calibration(three_gyros("    scale_factr: 1\n"), "typo.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message.rfind("typo.yaml:7: ", 0), 0U) << r.error().message;
  EXPECT_NE(r.error().message.find("unknown key 'scale_factr'"), std::string::npos);
}

TEST(CalibrationFile, RejectsNonUnitAxisFewGyrosAndText) {
  std::string non_unit = three_gyros("");
  non_unit.replace(non_unit.find("[1, 0, 0]"), 9, "[1, 0.5, 0]");
  const auto a = parse_calibration(non_unit, "axis.yaml");
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("axis.yaml:6"), std::string::npos) << a.error().message;
  EXPECT_NE(a.error().message.find("unit vector"), std::string::npos);

  const std::string two =
      "gyros:\n  - {id: 1, scale_factor_V_per_dps: 1, bias_V: 0, axis: [1,0,0]}\n"
      "  - {id: 2, scale_factor_V_per_dps: 1, bias_V: 0, axis: [0,1,0]}\n";
  const auto b = parse_calibration(two, "two.yaml");
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("at least 3"), std::string::npos);

  std::string text = three_gyros("");
  text.replace(text.find("bias_V: 0"), 9, "bias_V: zero");
  const auto c = parse_calibration(text, "text.yaml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("text.yaml:5"), std::string::npos) << c.error().message;

  EXPECT_FALSE(parse_calibration("gyros: [unclosed\n", "broken.yaml").ok());
  EXPECT_FALSE(read_calibration("/nonexistent/cal.yaml").ok());
}

}  // namespace
}  // namespace tetra
