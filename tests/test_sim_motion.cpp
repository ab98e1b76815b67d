// Truth motion: closed forms, exact returns after 360°, rates consistent with the attitude.
#include <gtest/gtest.h>

#include <cmath>

#include "tetra/core/frames.hpp"
#include "tetra/core/units.hpp"
#include "tetra/sim/motion.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::sim {
namespace {

TruthMotion make(const MotionSpec& spec) {
  auto m = TruthMotion::create(spec, 1);
  EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message);
  return m.value();
}

// Rate from the attitude alone: central difference of the attitude, 2·log(q(t−h)* ⊗ q(t+h))/(2h).
Eigen::Vector3d numeric_rate(const TruthMotion& m, double t, double h) {
  const Quaternion a = m.at(t - h).q_RB;
  const Quaternion b = m.at(t + h).q_RB;
  return quat_log(a.conjugate() * b) / (2.0 * h);
}

TEST(SimMotion, LabOrbitReturnsToIdentityAfter360DegreesAndMatchesClosedForm) {
  MotionSpec spec;
  spec.kind = MotionKind::kLabOrbit;
  spec.pitch_rate_dps = 0.06;
  const TruthMotion m = make(spec);
  // One turn at 0.06 deg/s takes 6000 s. 1e-12 rad: the closed form is evaluated directly, so only
  // rounding (~1e-16 per operation) remains.
  EXPECT_LT(angle_between(m.at(6000.0).q_RB, Quaternion::Identity()), 1e-12);
  for (double t : {0.0, 0.8, 1234.4, 2999.2, 5999.2}) {
    const double angle = 0.06 * kDegToRad * t;
    const Quaternion expected(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()));
    EXPECT_LT(angle_between(m.at(t).q_RB, expected), 1e-12) << "t = " << t;
    EXPECT_LT((m.at(t).omega_BR_B_rad_s - Eigen::Vector3d(0, 0.06 * kDegToRad, 0)).norm(), 1e-18);
    // The gyros also sense the Earth rate: C_LBᵀ·ω_e^L with C_LB = R_y(angle) (outer gimbal).
    const Eigen::Vector3d earth_B = turntable_earth_rate_B(0.0, angle, -23.2 * kDegToRad);
    EXPECT_LT((m.at(t).omega_BN_B_rad_s - m.at(t).omega_BR_B_rad_s - earth_B).norm(), 1e-18);
  }
}

TEST(SimMotion, OrbitPitchesAboutMinusYOncePerPeriod) {
  MotionSpec spec;
  spec.kind = MotionKind::kOrbit;
  spec.orbit_period_s = 6000.0;
  spec.acs.amplitude_deg = 0.0;
  const TruthMotion m = make(spec);
  EXPECT_LT(angle_between(m.at(6000.0).q_RB, Quaternion::Identity()), 1e-12);
  const double n = 2.0 * kPi / 6000.0;
  for (double t : {100.0, 1500.0, 3000.0, 4444.4}) {
    const Quaternion expected(Eigen::AngleAxisd(-n * t, Eigen::Vector3d::UnitY()));
    EXPECT_LT(angle_between(m.at(t).q_RB, expected), 1e-12) << "t = " << t;
  }
  EXPECT_LT((m.at(10.0).omega_BN_B_rad_s - Eigen::Vector3d(0, -n, 0)).norm(), 1e-18);
}

TEST(SimMotion, RatesAreTheDerivativeOfTheAttitudeWithAcsAndSlews) {
  auto sc = builtin_scenario("slews");
  ASSERT_TRUE(sc.ok());
  sc->motion.acs.amplitude_deg = 0.5;  // larger than default to make cross-coupling visible
  sc->motion.acs.peak_accel_dps2 = 1e-3;
  const TruthMotion m = make(sc->motion);
  // Times inside slews and between them. Central difference with h = 1e-3 s: truncation error
  // ~h²·|ω⃛| < 1e-12 rad/s, rounding ~1e-16/h = 1e-13 rad/s; 1e-10 rad/s leaves margin while the
  // rates themselves are ~1e-3..1e-2 rad/s, so a wrong sign or frame would fail by 7+ orders.
  for (double t : {10.0, 1230.0, 1260.0, 1300.0, 2000.0, 2450.0, 3650.0, 4850.0, 5500.0}) {
    const Eigen::Vector3d analytic = m.at(t).omega_BR_B_rad_s;
    EXPECT_LT((numeric_rate(m, t, 1e-3) - analytic).norm(), 1e-10) << "t = " << t;
  }
}

TEST(SimMotion, SlewIsRestToRestAndEndsAtTheCommandedAngle) {
  MotionSpec spec;
  spec.kind = MotionKind::kSlews;
  spec.acs.amplitude_deg = 0.0;
  spec.slews = {{Eigen::Vector3d::UnitZ(), 45.0, 100.0, 150.0}};
  const TruthMotion m = make(spec);
  MotionSpec plain = spec;
  plain.kind = MotionKind::kOrbit;
  const TruthMotion orbit = make(plain);
  // Before the slew: the plain orbit; after: orbit ⊗ exp(45° ẑ), to rounding (1e-12 rad).
  EXPECT_LT(angle_between(m.at(99.0).q_RB, orbit.at(99.0).q_RB), 1e-12);
  const Quaternion turned =
      orbit.at(400.0).q_RB * Quaternion(Eigen::AngleAxisd(45.0 * kDegToRad, Eigen::Vector3d::UnitZ()));
  EXPECT_LT(angle_between(m.at(400.0).q_RB, turned), 1e-12);
  // Rest to rest: at the start and the end the slew adds no rate (1e-15 rad/s: rounding of the
  // profile 1 − cos(2πu) at u = 0 and 1).
  for (double t : {100.0, 250.0}) {
    const Eigen::Vector3d extra =
        m.at(t).omega_BR_B_rad_s - m.at(t).q_RB.conjugate() * orbit.at(t).q_RB * orbit.at(t).omega_BR_B_rad_s;
    EXPECT_LT(extra.norm(), 1e-15) << "t = " << t;
  }
  // Mid-slew the profile's peak rate 2Φ/T about +Z.
  const Eigen::Vector3d mid = m.at(175.0).omega_BR_B_rad_s;
  EXPECT_NEAR(mid.z(), 2.0 * 45.0 * kDegToRad / 150.0, 1e-12);
}

TEST(SimMotion, AcsMotionStaysWithinItsStatedBounds) {
  MotionSpec spec;
  spec.kind = MotionKind::kOrbit;
  spec.acs.amplitude_deg = 0.05;
  spec.acs.peak_accel_dps2 = 1e-5;
  const TruthMotion m = make(spec);
  MotionSpec plain = spec;
  plain.acs.amplitude_deg = 0.0;
  const TruthMotion orbit = make(plain);
  EXPECT_NEAR(m.acs_peak_accel_dps2(), 1e-5, 1e-18);
  double max_dev = 0.0;
  double max_accel = 0.0;
  for (double t = 1.0; t < 6000.0; t += 1.0) {
    max_dev = std::max(max_dev, angle_between(m.at(t).q_RB, orbit.at(t).q_RB) * kRadToDeg);
    const Eigen::Vector3d a = (m.at(t + 0.5).omega_BR_B_rad_s - m.at(t - 0.5).omega_BR_B_rad_s) / 1.0;
    max_accel = std::max(max_accel, a.norm() * kRadToDeg);
  }
  // Three Euler angles each within ±A: total deviation ≤ √3·A; and the motion is really there
  // (over 6000 s, about 16 periods of the slower sinusoid, the deviation exceeds A/2).
  EXPECT_LE(max_dev, std::sqrt(3.0) * 0.05 * 1.0001);
  EXPECT_GE(max_dev, 0.025);
  // Each Euler acceleration within α, so the body acceleration within √3·α plus the coupling of the
  // ACS rate (≤ A·w₁ ≈ 1.5e-5 rad/s) with the orbit rate (1e-3 rad/s), ≈ 1.5e-8 rad/s² ≈ 0.1·α:
  // bound √3·α·1.1.
  EXPECT_LE(max_accel, std::sqrt(3.0) * 1e-5 * 1.1);
  EXPECT_GE(max_accel, 0.3e-5);
}

TEST(SimMotion, RejectsBadSpecs) {
  MotionSpec spec;
  spec.latitude_deg = 91.0;
  EXPECT_FALSE(TruthMotion::create(spec, 1).ok());
  spec = MotionSpec{};
  spec.kind = MotionKind::kSlews;
  spec.slews = {{Eigen::Vector3d::Zero(), 10.0, 0.0, 10.0}};
  auto bad = TruthMotion::create(spec, 1);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("slews[0].axis"), std::string::npos) << bad.error().message;
}

TEST(SimMotion, LabOrbitLogIntegratesTo360DegreesWithTheTruthCalibration) {
  auto sc = builtin_scenario("lab-orbit");
  ASSERT_TRUE(sc.ok());
  Truth truth;
  auto log = simulate_log(*sc, SimOptions{}, &truth);
  ASSERT_TRUE(log.ok()) << log.error().message;
  ASSERT_EQ(log->epochs(), 7500u);  // 100 min every 0.8 s, as in the seed
  const Calibration& cal = sc->unit;
  const Eigen::MatrixX3d H = cal.axes_B();
  const Eigen::Matrix3Xd pinv = (H.transpose() * H).inverse() * H.transpose();
  const double dt = 0.8;
  const double lat = sc->motion.latitude_deg * kDegToRad;
  Quaternion q = Quaternion::Identity();
  double pitch_deg = 0.0;
  for (std::size_t k = 0; k < log->epochs(); ++k) {
    Eigen::VectorXd y(cal.gyro_count());
    for (int i = 0; i < cal.gyro_count(); ++i) {
      const auto& g = cal.gyros[static_cast<std::size_t>(i)];
      y[i] = (log->value(k, i) - g.bias_V) / g.scale_factor_V_per_dps * kDegToRad;
    }
    // Remove the Earth rate with the estimated attitude (the seed discounted it the same way).
    const Eigen::Vector3d omega = pinv * y - q.conjugate() * earth_rate_L(lat);
    q = propagate(q, omega, dt);
    pitch_deg += omega.y() * kRadToDeg * dt;
  }
  // 360° after 100 min. Noise budget (1σ): ARW 3e-5·√6000 ≈ 2.3e-3°, bias instability (σ_GM
  // 5.4e-6 deg/s, T_c 100 s) ≈ σ√(2·T_c·T) ≈ 6e-3°, combined over the 4 gyros ≲ 1e-2°: ±0.05°.
  EXPECT_NEAR(pitch_deg, 360.0, 0.05);
  EXPECT_LT(angle_between(q, truth.q_RB.back() * quat_exp(Eigen::Vector3d(0, 0.06 * kDegToRad * 0.8, 0))) *
                kRadToDeg,
            0.05);
}

}  // namespace
}  // namespace tetra::sim
