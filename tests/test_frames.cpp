// Turntable kinematics and the Earth rate (docs/interfaces.md §1).
#include <cmath>

#include <gtest/gtest.h>

#include "tetra/core/frames.hpp"
#include "tetra/core/units.hpp"

namespace tetra {
namespace {

TEST(Frames, EarthRateInLab) {
  const Eigen::Vector3d w = earth_rate_L(-23.2 * kDegToRad);
  EXPECT_NEAR(w.norm(), kEarthRate_rad_s, 1e-18);
  EXPECT_LT(w.x(), 0.0);  // southern hemisphere: the "up" component is negative
  EXPECT_DOUBLE_EQ(w.y(), 0.0);
}

TEST(Frames, TurntableBodyRateMatchesNumericalDerivative) {
  // ω_B from the kinematics must equal the body rate implied by C_LB(t): [ω_B×] = C_LBᵀ Ċ_LB.
  const double inner = 0.7;
  const double outer = -1.1;
  const double inner_dot = 0.05;
  const double outer_dot = -0.08;
  const double h = 1e-6;
  const Eigen::Matrix3d c0 = turntable_C_LB(inner - h * inner_dot, outer - h * outer_dot);
  const Eigen::Matrix3d c1 = turntable_C_LB(inner + h * inner_dot, outer + h * outer_dot);
  const Eigen::Matrix3d skew = turntable_C_LB(inner, outer).transpose() * (c1 - c0) / (2 * h);
  const Eigen::Vector3d numeric(skew(2, 1), skew(0, 2), skew(1, 0));
  const Eigen::Vector3d analytic = turntable_rate_B(inner, inner_dot, outer_dot);
  EXPECT_LT((numeric - analytic).norm(), 1e-9) << numeric.transpose() << " vs " << analytic.transpose();
}

TEST(Frames, EarthRateInBodyAtRestIsLabRate) {
  const double lat = 10 * kDegToRad;
  EXPECT_TRUE(turntable_earth_rate_B(0, 0, lat).isApprox(earth_rate_L(lat), 1e-15));
  // Inner at 180°: Y and Z flip.
  const Eigen::Vector3d flipped = turntable_earth_rate_B(kPi, 0, lat);
  EXPECT_NEAR(flipped.z(), -earth_rate_L(lat).z(), 1e-18);
}

}  // namespace
}  // namespace tetra
