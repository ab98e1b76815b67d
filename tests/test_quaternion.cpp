// Quaternion convention (docs/interfaces.md §1): Hamilton, body→reference, q ← q ⊗ exp(½ ω Δt).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tetra/core/attitude.hpp"

#include "tetra/core/quaternion.hpp"
#include "tetra/core/units.hpp"

namespace tetra {
namespace {

TEST(Quaternion, ExpLogRoundTripNearZeroAndPi) {
  // Sophus-style property test: log(exp(v)) = v for angles from 1e-12 to π − 1e-6 (1e-12 relative).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (const double angle : {1e-12, 1e-9, 1e-6, 1e-4, 0.99e-4, 1.01e-4, 0.1, 1.0, 3.0, kPi - 1e-6}) {
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
      const Eigen::Vector3d v = angle * axis;
      const Eigen::Vector3d back = quat_log(quat_exp(v));
      EXPECT_LT((back - v).norm(), 1e-12 * std::max(1.0, angle)) << "angle " << angle;
      EXPECT_NEAR(quat_exp(v).norm(), 1.0, 1e-15);
    }
  }
}

TEST(Quaternion, BodyToReferenceConvention) {
  // A body rotated +90° about Z: body X points along reference Y.
  const Quaternion q = quat_exp(Eigen::Vector3d(0, 0, kPi / 2));
  const Eigen::Vector3d x_ref = q * Eigen::Vector3d::UnitX();
  EXPECT_TRUE(x_ref.isApprox(Eigen::Vector3d::UnitY(), 1e-15));
  const auto wxyz = to_wxyz(q);
  EXPECT_NEAR(wxyz[0], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(wxyz[3], std::sqrt(0.5), 1e-15);
}

TEST(Quaternion, PropagationIsExactForConstantRate) {
  // 3600 steps of 0.1 s at 1 deg/s about a tilted axis: exactly 360° → identity (to 1e-12 rad).
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -0.5).normalized();
  const Eigen::Vector3d omega = axis * kDegToRad;
  Quaternion q = Quaternion::Identity();
  for (int i = 0; i < 3600; ++i) q = propagate(q, omega, 0.1);
  EXPECT_LT(angle_between(q, Quaternion::Identity()), 1e-12);
  // Body-frame composition: propagating in body frame after a first rotation.
  const Quaternion q0 = quat_exp(Eigen::Vector3d(0.3, 0, 0));
  const Quaternion q1 = propagate(q0, Eigen::Vector3d(0, 0.2, 0), 1.0);
  EXPECT_LT(angle_between(q1, q0 * quat_exp(Eigen::Vector3d(0, 0.2, 0))), 1e-15);
}

TEST(AttitudePropagator, ABoundTurnsWithTheBody) {
  // An angle error already made (a fault's, before its isolation) is fixed in the reference frame: a body
  // that turns moves it from one body axis to another. A bound of 1e-3 rad on body Z, then 90° about X in 900
  // steps: the bound is on body Y (to 1e-12 rad), and none is left on Z. The box is the smallest about the
  // turned one: at 45° each of Y and Z carries cos 45° of it (the rotated error lies on their diagonal).
  // Before, the bound stayed on the body axis it was added on (Z), where the error no longer was.
  AttitudePropagator a(Quaternion::Identity(), std::nullopt);
  a.add_bound(Eigen::Vector3d(0.0, 0.0, 1e-3));
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const Eigen::Vector3d omega(kPi / 2 / 90.0, 0.0, 0.0);  // [rad/s] 90° in 90 s
  for (int k = 0; k < 450; ++k) (void)a.step(omega, 0.1, zero, zero, zero);
  EXPECT_NEAR(a.sigma_rad().y(), std::sqrt(0.5) * 1e-3, 1e-12);
  EXPECT_NEAR(a.sigma_rad().z(), std::sqrt(0.5) * 1e-3, 1e-12);
  for (int k = 0; k < 450; ++k) (void)a.step(omega, 0.1, zero, zero, zero);
  EXPECT_NEAR(a.sigma_rad().x(), 0.0, 1e-15);
  EXPECT_NEAR(a.sigma_rad().y(), 1e-3, 1e-12);
  EXPECT_LT(a.sigma_rad().z(), 1e-12);
  // What a step adds in the current body axes is kept in those: 1e-4 rad/s on Y for 1 s is 1e-4 rad more
  // on Y, after the turn as before it.
  (void)a.step(zero, 1.0, zero, zero, Eigen::Vector3d(0.0, 1e-4, 0.0));
  EXPECT_NEAR(a.sigma_rad().y(), 1.1e-3, 1e-12);
  // A reset forgets the bound.
  a.reset(a.q_RB());
  EXPECT_EQ(a.sigma_rad(), zero);
}

}  // namespace
}  // namespace tetra
