// `tetra allan --kalibr`: Kalibr's gyro keys from the fitted N and K, combined over the gyros' axes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "test_support.hpp"
#include "tetra/core/allan_kalibr.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/units.hpp"

namespace tetra {
namespace {

// The seed's geometry, exactly: gyro 4 on X, gyros 1-3 at 54.736° from X and 120° apart, so
// Σ h hᵀ = diag(2, 1, 1).
Calibration ideal_unit() {
  Calibration cal = seed_as_built_unit();
  const double c = 1.0 / std::sqrt(3.0), s = std::sqrt(2.0 / 3.0);
  for (int i = 0; i < 3; ++i) {
    const double a = 2.0 * kPi * i / 3.0;
    cal.gyros[static_cast<std::size_t>(i)].axis_B = Eigen::Vector3d(c, s * std::cos(a), s * std::sin(a));
  }
  cal.gyros[3].axis_B = Eigen::Vector3d::UnitX();
  return cal;
}

allan::LogAllan analysis(double n_dps_rts, std::optional<double> k_dps_per_rts) {
  allan::LogAllan a;
  a.units = "deg/s";
  a.tau0_s = 0.01;
  for (int id = 1; id <= 4; ++id) {
    allan::GyroAllan g;
    g.id = id;
    g.result.fit.value[allan::kN] = n_dps_rts;
    g.result.fit.observed[allan::kN] = true;
    g.result.fit.value[allan::kK] = k_dps_per_rts.value_or(0.0);
    g.result.fit.observed[allan::kK] = k_dps_per_rts.has_value();
    a.gyros.push_back(g);
  }
  return a;
}

TEST(AllanKalibr, BodyAxisValuesInRadiansFromTheGeometry) {
  // Equal gyros: the Y and Z axes carry N (and K) itself, X N/√2; the file gives the largest. Exact up
  // to rounding: 1e-12 relative.
  const auto noise = allan::kalibr_gyro_noise(analysis(3e-5, 2e-7), ideal_unit());
  ASSERT_TRUE(noise.ok()) << noise.error().message;
  EXPECT_NEAR(noise->noise_density_rad_s_rtHz, 3e-5 * kDegToRad, 1e-12 * 3e-5 * kDegToRad);
  ASSERT_TRUE(noise->random_walk_rad_s2_rtHz.has_value());
  EXPECT_NEAR(*noise->random_walk_rad_s2_rtHz, 2e-7 * kDegToRad, 1e-12 * 2e-7 * kDegToRad);
  EXPECT_DOUBLE_EQ(noise->update_rate_hz, 100.0);

  const std::string yaml = allan::format_kalibr(*noise, "/tetra/tetra_1/imu");
  EXPECT_NE(yaml.find("rostopic: /tetra/tetra_1/imu\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("update_rate: 100"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("gyroscope_noise_density: 5.23599e-07"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("gyroscope_random_walk: 3.49066e-09"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("# accelerometer_noise_density"), std::string::npos) << yaml;
}

TEST(AllanKalibr, UnobservedRandomWalkIsACommentAndUnobservedWhiteNoiseAFailure) {
  const auto noise = allan::kalibr_gyro_noise(analysis(3e-5, std::nullopt), ideal_unit());
  ASSERT_TRUE(noise.ok());
  EXPECT_FALSE(noise->random_walk_rad_s2_rtHz.has_value());
  const std::string yaml = allan::format_kalibr(*noise, "/x");
  EXPECT_NE(yaml.find("# gyroscope_random_walk: not observed"), std::string::npos) << yaml;
  EXPECT_EQ(yaml.find("\ngyroscope_random_walk:"), std::string::npos) << yaml;

  auto no_n = analysis(3e-5, std::nullopt);
  no_n.gyros[1].result.fit.observed[allan::kN] = false;
  EXPECT_FALSE(allan::kalibr_gyro_noise(no_n, ideal_unit()).ok());
  auto volts = analysis(3e-5, std::nullopt);
  volts.units = "V";
  EXPECT_FALSE(allan::kalibr_gyro_noise(volts, ideal_unit()).ok());
}

TEST(AllanKalibr, CommandLineNeedsACalibration) {
  test::TempDir dir;
  test::write_file(dir.file("log.csv"), "# units=dps\ntime_s,g1,g2,g3,g4\n0,0,0,0,0\n0.01,0,0,0,0\n");
  const auto r = test::run_tetra("allan " + dir.file("log.csv") + " --kalibr " + dir.file("imu.yaml"));
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find("--kalibr needs --calibration"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace tetra
