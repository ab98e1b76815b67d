// Closed-loop simulation: rigid-body dynamics, guidance, controller, and the loop closed
// through the fusion pipeline in process, with and without exclusion of a faulty gyro.

#include <gtest/gtest.h>

#include <cmath>

#include "test_support.hpp"
#include "tetra/core/units.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/closed_loop.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/dynamics.hpp"
#include "tetra/sim/guidance.hpp"
#include "tetra/sim/pointing_report.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::sim {
namespace {

ClosedLoopSpec quiet_spec() {
  ClosedLoopSpec spec;
  spec.disturbance.gravity_gradient = false;
  return spec;
}

// The true attitude and rate as the estimate: tests the controller alone.
class TruthEstimator final : public Estimator {
 public:
  explicit TruthEstimator(double stop_after_s = INFINITY) : stop_after_s_(stop_after_s) {}
  Result<EstimatorOutput> estimate(const SimEpoch& epoch) override {
    EstimatorOutput out;
    if (epoch.time_s >= stop_after_s_) return out;
    fdi::AttitudeEstimate e;
    e.stamp_ns = epoch.stamp_ns;
    e.q_RB = epoch.truth_q_RB;
    e.omega_BR_B_rad_s = epoch.omega_BN_B_rad_s;
    out.latest = e;
    return out;
  }

 private:
  double stop_after_s_;
};

Scenario loop_scenario(const ClosedLoopSpec& spec, double duration_s) {
  Scenario sc = builtin_scenario("orbit").value();
  sc.duration_s = duration_s;
  sc.reference.rate_hz = 0.0;
  sc.closed_loop = spec;
  return sc;
}

TEST(ClosedLoopDynamics, TorqueFreeBodyKeepsMomentumAndEnergy) {
  ClosedLoopSpec spec = quiet_spec();
  spec.inertia_kg_m2 << 12.0, 0.5, -0.3, 0.5, 10.0, 0.2, -0.3, 0.2, 8.0;
  const Spacecraft craft(spec, 6000.0);
  BodyState s;
  s.omega_BN_B_rad_s = Eigen::Vector3d(1.0, -2.0, 0.5) * kDegToRad;
  s.h_wheels_Nms = Eigen::VectorXd::Constant(4, 0.05);
  const Eigen::VectorXd no_torque = Eigen::VectorXd::Zero(4);
  const auto momentum_N = [&] {
    return Eigen::Vector3d(s.q_NB *
                           (spec.inertia_kg_m2 * s.omega_BN_B_rad_s + craft.wheel_axes() * s.h_wheels_Nms));
  };
  const auto energy = [&] { return 0.5 * s.omega_BN_B_rad_s.dot(spec.inertia_kg_m2 * s.omega_BN_B_rad_s); };
  const Eigen::Vector3d h0 = momentum_N();
  const double e0 = energy();
  for (int k = 0; k < 5000; ++k) craft.step(s, no_torque, 0.02 * k, 0.02);  // 100 s at 50 Hz
  // RK4's global error at ω·h ≈ 8e-4 rad is ~1e-13 relative; 1e-9 leaves room for rounding.
  EXPECT_LT((momentum_N() - h0).norm() / h0.norm(), 1e-9);
  EXPECT_LT(std::abs(energy() - e0) / e0, 1e-9);
}

// A tumbling body with a full inertia, every disturbance, and wheel torques that change each 0.1-s period,
// stepped at 30 Hz (three steps a period: step times that do not all add up exactly).
struct DynamicsTrace {
  Quaternion q_NB;
  Eigen::Vector3d omega_BN_B_rad_s;
  Eigen::VectorXd h_wheels_Nms;
};

DynamicsTrace run_dynamics_trace(int wheels, bool in_periods) {
  ClosedLoopSpec spec;
  spec.inertia_kg_m2 << 12.0, 0.5, -0.3, 0.5, 10.0, 0.2, -0.3, 0.2, 8.0;
  spec.wheels.count = wheels;
  spec.disturbance.constant_Nm = Eigen::Vector3d(2e-6, -1e-6, 1.5e-6);
  spec.disturbance.periodic_Nm = Eigen::Vector3d(1e-6, 2e-6, 1e-6);
  spec.disturbance.gravity_gradient = true;
  const Spacecraft craft(spec, 6000.0);
  BodyState s;
  s.q_NB = quat_exp(Eigen::Vector3d(0.1, -0.2, 0.3));
  s.omega_BN_B_rad_s = Eigen::Vector3d(10.0, -20.0, 5.0) * kDegToRad;  // the wheels' term dominant in ω̇
  s.h_wheels_Nms = Eigen::VectorXd::LinSpaced(wheels, -0.5, 0.5);
  Eigen::VectorXd tau(wheels);
  const double h = 0.1 / 3.0;
  for (int k = 0; k < 6000; ++k) {
    for (int i = 0; i < wheels; ++i) tau[i] = 1e-2 * std::sin(0.01 * k + i);
    if (in_periods) {
      craft.advance(s, tau, 0.1 * k, h, 3);
    } else {
      for (int i = 0; i < 3; ++i) craft.step(s, tau, 0.1 * k + i * h, h);
    }
  }
  return {s.q_NB, s.omega_BN_B_rad_s, s.h_wheels_Nms};
}

// The rigid-body step's every bit, recorded (as hexadecimal floats) from the implementation before the
// allocation-free one (each evaluation's own wheel vectors and matrix-vector products): a change of the
// arithmetic's order in the step shows here after its 18,000 steps (summing G·h's wheels in reverse order
// does, for the four-wheel pyramid; with three wheels on the axes the order cannot matter).
TEST(ClosedLoopDynamics, StepsReproduceTheirRecordedBits) {
  const DynamicsTrace four = run_dynamics_trace(4, false);
  EXPECT_EQ(four.q_NB.coeffs(), Eigen::Vector4d(0x1.31abdc36d302fp-1, -0x1.523b5e4b4d3aap-1,
                                                -0x1.1f539884647ebp-5, 0x1.d0b2535910e28p-2));  // x y z w
  EXPECT_EQ(four.omega_BN_B_rad_s,
            Eigen::Vector3d(0x1.3be0510611895p-2, -0x1.0224a5ab41a5ep-2, -0x1.8affd42cff5e7p-5));
  EXPECT_EQ(four.h_wheels_Nms, Eigen::Vector4d(-0x1.37eb23b8e9e5ap-2, -0x1.5ff0f2312520dp-4,
                                               0x1.df72c93336e43p-5, 0x1.35a83f0891acfp-2));
  const DynamicsTrace three = run_dynamics_trace(3, false);
  EXPECT_EQ(three.q_NB.coeffs(), Eigen::Vector4d(-0x1.52db29ea6fb0fp-2, -0x1.edb72ee3d9004p-3,
                                                 -0x1.79c576ba75fd1p-2, 0x1.ab3aee9d0df4ap-1));
  EXPECT_EQ(three.omega_BN_B_rad_s,
            Eigen::Vector3d(0x1.3569fc321f988p-2, -0x1.6ec06921928a9p-5, -0x1.06c4fa7a31f09p-2));
  EXPECT_EQ(three.h_wheels_Nms,
            Eigen::Vector3d(-0x1.37eb23b8e9e5ap-2, 0x1.4ab9b87985865p-4, 0x1.9143ae7bbc2c1p-2));
}

// advance() over a period is its steps one by one, bit for bit (the carried time terms are the same ones).
TEST(ClosedLoopDynamics, AdvanceIsItsStepsOneByOne) {
  for (int wheels : {3, 4}) {
    const DynamicsTrace steps = run_dynamics_trace(wheels, false);
    const DynamicsTrace periods = run_dynamics_trace(wheels, true);
    EXPECT_EQ(steps.q_NB.coeffs(), periods.q_NB.coeffs()) << wheels << " wheels";
    EXPECT_EQ(steps.omega_BN_B_rad_s, periods.omega_BN_B_rad_s) << wheels << " wheels";
    EXPECT_EQ(steps.h_wheels_Nms, periods.h_wheels_Nms) << wheels << " wheels";
  }
}

TEST(ClosedLoopDynamics, GravityGradientTorqueOfATiltedBody) {
  ClosedLoopSpec spec;
  const Spacecraft craft(spec, 6000.0);
  const double n = 2.0 * kPi / 6000.0;
  // Aligned with LVLH (principal axes along the orbit frame): no torque.
  EXPECT_LT(craft.disturbance_B_Nm(Quaternion::Identity(), 0.0).norm(), 1e-18);
  // Tilted by θ about Y: |τ| = 3n²·|I_z − I_x|·sinθ·cosθ, about Y (exact formula, 1e-12 relative for
  // rounding).
  const double theta = 20.0 * kDegToRad;
  const Eigen::Vector3d tau = craft.disturbance_B_Nm(quat_exp(Eigen::Vector3d(0.0, theta, 0.0)), 0.0);
  const double expected = 3.0 * n * n * std::abs(8.0 - 12.0) * std::sin(theta) * std::cos(theta);
  EXPECT_NEAR(std::abs(tau.y()), expected, 1e-12 * expected);
  EXPECT_LT(std::hypot(tau.x(), tau.z()), 1e-12 * expected);
}

TEST(ClosedLoopGuidance, TrapezoidRespectsLimitsAndReachesTheAngle) {
  const double w = 0.5 * kDegToRad;
  const double a = 0.02 * kDegToRad;
  for (double angle_deg : {30.0, -5.0, 2.0}) {  // trapezoid, negative, triangle (2° < w²/a = 12.5°)
    const double total = angle_deg * kDegToRad;
    const double t_end = trapezoid_duration_s(total, w, a);
    double integrated = 0.0;
    const double dt = 0.001;
    for (double t = 0.0; t < t_end + 1.0; t += dt) {
      const SlewProfile p = trapezoid_profile(total, w, a, t);
      EXPECT_LE(std::abs(p.rate_rad_s), w * (1.0 + 1e-12));
      EXPECT_LE(std::abs(p.accel_rad_s2), a * (1.0 + 1e-12));
      integrated += p.rate_rad_s * dt;
    }
    EXPECT_DOUBLE_EQ(trapezoid_profile(total, w, a, t_end + 1.0).angle_rad, total);
    // Rectangle-rule integral of the rate: error ≤ peak rate · dt = 9e-6 rad.
    EXPECT_NEAR(integrated, total, 1e-5) << angle_deg;
  }
}

TEST(ClosedLoopController, StepResponseSettlesAtTheStatedBandwidth) {
  ClosedLoopSpec spec = quiet_spec();
  spec.pointing.mode = PointingMode::kInertial;
  spec.initial_error_deg = Eigen::Vector3d(0.1, -0.05, 0.07);  // small enough not to saturate the wheels
  spec.controller.bandwidth_hz = 0.05;
  spec.controller.damping = 0.7;
  auto sim = ClosedLoopSimulator::create(loop_scenario(spec, 60.0), {}).value();
  TruthEstimator truth;
  const auto record = run_closed_loop(sim, truth).value();
  // ζ = 0.7, ω_n = 2π·0.05: the error envelope falls as exp(−ζω_n t) = 1.5e-4 at 40 s, from 0.13°
  // to 2e-5°: below 0.001° with a factor 50 of margin (the linear model ignores gyroscopic terms).
  for (const PointingSample& s : record.series) {
    if (s.time_s >= 40.0) {
      ASSERT_LT(s.error_deg, 0.001) << s.time_s;
    }
  }
  EXPECT_EQ(record.series.front().torque_limited, false);
  EXPECT_EQ(record.counters.safe_epochs, 0u);
}

TEST(ClosedLoopController, SlewFollowsTheProfileWithinItsLimits) {
  ClosedLoopSpec spec = quiet_spec();
  spec.pointing.mode = PointingMode::kInertial;
  spec.pointing.slews = {{Eigen::Vector3d::UnitZ(), 20.0, 10.0}};
  auto sim = ClosedLoopSimulator::create(loop_scenario(spec, 200.0), {}).value();
  TruthEstimator truth;
  const auto record = run_closed_loop(sim, truth).value();
  const double slew_end = 10.0 + trapezoid_duration_s(20.0 * kDegToRad, 0.5 * kDegToRad, 0.02 * kDegToRad);
  double worst_during = 0.0;
  for (const PointingSample& s : record.series) {
    if (s.time_s < slew_end) worst_during = std::max(worst_during, s.error_deg);
    if (s.time_s > slew_end + 40.0) {
      ASSERT_LT(s.error_deg, 0.01) << s.time_s;
    }
  }
  // With the rate and acceleration feed-forward the body tracks the profile closely (stated: 0.05°).
  EXPECT_LT(worst_during, 0.05);
  const Quaternion target = quat_exp(Eigen::Vector3d(0.0, 0.0, 20.0 * kDegToRad));
  EXPECT_LT(angle_between(sim.state().q_NB, target) * kRadToDeg, 0.01);
}

TEST(ClosedLoopController, StaleAttitudeHoldsThenSafeMode) {
  ClosedLoopSpec spec = quiet_spec();
  spec.controller.hold_after_s = 0.5;
  spec.controller.safe_after_s = 2.0;
  auto sim = ClosedLoopSimulator::create(loop_scenario(spec, 20.0), {}).value();
  TruthEstimator stops(10.0);  // no estimate from t = 10 s
  const auto record = run_closed_loop(sim, stops).value();
  // 10 Hz: the last estimate is of t = 9.9 s; hold while its age is in (0.5, 2] s: t = 10.5 .. 11.9.
  EXPECT_EQ(record.counters.hold_epochs, 15u);
  EXPECT_EQ(record.counters.safe_entries, 1u);
  EXPECT_EQ(record.counters.safe_epochs, 80u);  // t = 12.0 .. 19.9
  EXPECT_EQ(record.series.back().control, ControlState::kSafe);
}

// Two gyros lost (4 → 2: the rate is no longer determined, the estimate is LOST): the controller stops
// steering on it and holds the wheels (safe mode, zero torque). Before, it kept steering on the lost
// estimate and the spacecraft went unstable (0.05° → 6° in 200 s, wheel torques pinned at their limit).
TEST(ClosedLoopController, LostAttitudeHoldsTheWheels) {
  Scenario sc = read_scenario(test::source_path("examples/sim/closed_loop_nadir.yaml")).value();
  sc.duration_s = 1200.0;
  sc.faults = {parse_fault_spec("gyro=1,kind=zero,at=1000").value(),
               parse_fault_spec("gyro=2,kind=zero,at=1000").value()};
  auto sim = ClosedLoopSimulator::create(sc, {}).value();
  auto estimator = PipelineEstimator::create(sc.unit, {}, sim.initial_q_NB()).value();
  const auto record = run_closed_loop(sim, estimator).value();
  const PointingSummary summary = summarize(record, sim);
  std::optional<double> lost_at_s;
  Eigen::VectorXd speed_at_loss;
  double max_after_deg = 0.0;
  for (const PointingSample& s : record.series) {
    if (!lost_at_s && s.mode == fdi::Mode::kLost) {
      lost_at_s = s.time_s;
      speed_at_loss = s.wheel_speed_rpm;
    }
    if (!lost_at_s) continue;
    max_after_deg = std::max(max_after_deg, s.error_deg);
    ASSERT_EQ(s.control, ControlState::kSafe) << s.time_s;
    ASSERT_TRUE(s.wheel_torque_Nm.isZero(0.0)) << s.time_s;  // exactly zero: nothing drives the wheels
    ASSERT_FALSE(s.torque_limited) << s.time_s;
    ASSERT_EQ(s.wheel_speed_rpm, speed_at_loss) << s.time_s;  // held: the wheels keep their speed
  }
  ASSERT_TRUE(lost_at_s);
  // The pipeline declares LOST within its isolation time of the onset (0.9 s measured; 2 s stated).
  EXPECT_LT(*lost_at_s, 1002.0);
  EXPECT_EQ(summary.counters.lost_epochs,
            record.series.size() - static_cast<std::size_t>(std::llround(*lost_at_s * sc.rate_hz)));
  // No instability: the body drifts at the rate it had when the estimate was lost (0.014 deg/s measured,
  // left by the 0.9 s of steering on the failing estimate before LOST) plus the disturbances' torque
  // (≤ 5.1e-6 N·m on 8 kg·m²: ½·α·t² = 0.73° over 200 s): 2.8° measured at 200 s; 4° states it with margin,
  // against 6° and rising with the torques pinned before.
  EXPECT_LT(max_after_deg, 4.0);
  EXPECT_FALSE(summary.within_bound_after_recovery);
}

// Anti-windup: the integral of the error is frozen while the command is limited, and resumes when it
// is not.
TEST(ClosedLoopController, IntegratorFrozenWhileSaturated) {
  ClosedLoopSpec spec = quiet_spec();
  spec.pointing.mode = PointingMode::kInertial;
  spec.controller.integral_time_s = 100.0;
  AttitudeController controller(spec, wheel_axes_B(spec.wheels), 0.0);
  const Eigen::VectorXd h = Eigen::VectorXd::Zero(4);
  const double dt_s = 0.1;
  AttitudeKnowledge far;  // 30° off: I·ω_n²·θ far beyond the wheels' torque
  far.q_NB = quat_exp(Eigen::Vector3d(30.0 * kDegToRad, 0.0, 0.0));
  for (int k = 0; k < 1000; ++k) {
    far.time_s = k * dt_s;
    const ControlOutput out = controller.command(far.time_s, far, h, dt_s);
    ASSERT_TRUE(out.torque_limited) << k;
  }
  // Only the first period (before any command was known to be limited) integrated: θ·dt = 0.052 rad·s.
  EXPECT_NEAR(controller.integral_rad_s().norm(), 2.0 * std::sin(15.0 * kDegToRad) * dt_s, 1e-12);
  AttitudeKnowledge near = far;  // 0.001°: well within the wheels' torque
  near.q_NB = quat_exp(Eigen::Vector3d(1e-3 * kDegToRad, 0.0, 0.0));
  const double before = controller.integral_rad_s().x();
  for (int k = 1000; k < 1010; ++k) {
    near.time_s = k * dt_s;
    ASSERT_FALSE(controller.command(near.time_s, near, h, dt_s).torque_limited) << k;
  }
  // 9 unlimited periods after the first (which followed a limited one) each add θ·dt.
  EXPECT_NEAR(controller.integral_rad_s().x() - before, 9.0 * 1e-3 * kDegToRad * dt_s, 1e-12);
}

// `recovered` judges every segment: a fault-free run whose wheels saturate under a disturbance they
// cannot hold and that tumbles is not recovered.
TEST(ClosedLoopSummary, FaultFreeTumbleIsNotRecovered) {
  ClosedLoopSpec spec = quiet_spec();
  spec.pointing.mode = PointingMode::kInertial;
  spec.wheels.max_momentum_Nms = 0.05;
  spec.disturbance.constant_Nm = Eigen::Vector3d(0.0, 0.0, 1e-3);  // 0.05 N·m·s per 50 s: saturates
  auto sim = ClosedLoopSimulator::create(loop_scenario(spec, 600.0), {}).value();
  TruthEstimator truth;
  const auto record = run_closed_loop(sim, truth).value();
  const PointingSummary summary = summarize(record, sim);
  ASSERT_EQ(summary.segments.size(), 1u);  // no fault: one segment
  EXPECT_GT(summary.max_wheel_momentum_fraction, 0.99);
  EXPECT_GT(summary.momentum_limited_s, 0.0);
  EXPECT_GT(summary.max_deg, 90.0);  // tumbling (1.25e-4 rad/s² once saturated, from about 115 s)
  EXPECT_FALSE(summary.segments.front().recover_s);
  EXPECT_FALSE(summary.within_bound_after_recovery);
  EXPECT_NE(summary_json(summary).find("\"recovered\": false"), std::string::npos);
  // The same spacecraft without the disturbance holds its attitude: recovered, after 0 s.
  spec.disturbance.constant_Nm.setZero();
  auto calm = ClosedLoopSimulator::create(loop_scenario(spec, 60.0), {}).value();
  const PointingSummary calm_summary = summarize(run_closed_loop(calm, truth).value(), calm);
  EXPECT_TRUE(calm_summary.within_bound_after_recovery);
  EXPECT_EQ(calm_summary.segments.front().recover_s, 0.0);
}

// Slews are checked against the pointing's limits when the file is read: one that starts while the one
// before is under way (their rates and accelerations would add) is refused naming it and its line.
TEST(ClosedLoopScenario, OverlappingSlewsAreRefused) {
  const std::string head =
      "scenario: orbit\nclosed_loop:\n  pointing:\n    mode: inertial\n    max_rate_dps: 0.5\n"
      "    max_accel_dps2: 0.02\n    slews:\n      - {axis: z, angle_deg: 20, start_s: 10}\n";
  // 20° at 0.5 deg/s and 0.02 deg/s²: 25 s up, 15 s coast, 25 s down: under way until 75 s.
  const auto bad = parse_scenario(head + "      - {axis: x, angle_deg: 5, start_s: 60}\n", "x.yaml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("x.yaml:9"), std::string::npos) << bad.error().message;
  EXPECT_NE(
      bad.error().message.find("pointing.slews[1].start_s 60 s: slews[0] is still under way until 75 s"),
      std::string::npos)
      << bad.error().message;
  EXPECT_TRUE(parse_scenario(head + "      - {axis: x, angle_deg: 5, start_s: 75}\n", "x.yaml"));
}

struct FaultRun {
  PointingSummary with;
  PointingSummary without;
};

FaultRun nadir_fault_run(const std::string& fault, std::uint64_t seed, bool star_tracker = true) {
  Scenario sc = read_scenario(test::source_path("examples/sim/closed_loop_nadir.yaml")).value();
  sc.duration_s = 900.0;
  if (!star_tracker) sc.reference.rate_hz = 0.0;
  sc.faults = {parse_fault_spec(fault).value()};
  FaultRun out;
  for (bool exclusion : {true, false}) {
    SimOptions options;
    options.seed = seed;
    auto sim = ClosedLoopSimulator::create(sc, options).value();
    fdi::PipelineConfig config;
    config.exclusion_enabled = exclusion;
    auto estimator = PipelineEstimator::create(sc.unit, config, sim.initial_q_NB()).value();
    const auto record = run_closed_loop(sim, estimator).value();
    (exclusion ? out.with : out.without) = summarize(record, sim);
  }
  return out;
}

// Acceptance: nadir pointing, a biased gyro mid-run. With FDI the pointing error stays within the
// stated bound (0.05°) after the fault. Gyros only (the scenario's star tracker off): with exclusion disabled
// the error exceeds the bound. With the star tracker, the attitude filter's bias states absorb the part of
// the fault the reference sees, so without exclusion the error stays larger than with it but need not exceed
// the bound. Three seeds, two gyros. A stuck gyro: isolated and within the bound with FDI; without exclusion
// its effect on nadir pointing (a nearly constant rate) depends on the seed, so only the FDI side is
// asserted.
TEST(ClosedLoopAcceptance, FaultyGyroWithAndWithoutExclusion) {
  for (const bool star_tracker : {false, true}) {
    for (const char* fault : {"gyro=2,kind=bias,at=450,size=0.01", "gyro=4,kind=bias,at=450,size=0.005",
                              "gyro=3,kind=stuck,at=450"}) {
      const bool stuck = std::string(fault).find("stuck") != std::string::npos;
      for (std::uint64_t seed : {1u, 2u, 3u}) {
        const FaultRun run = nadir_fault_run(fault, seed, star_tracker);
        const std::string what = std::string(fault) + " seed " + std::to_string(seed) +
                                 (star_tracker ? " star tracker" : " gyros only");
        std::printf("%s: max error after the fault %.4f deg with exclusion, %.4f without\n", what.c_str(),
                    run.with.segments[1].max_deg, run.without.segments[1].max_deg);
        ASSERT_EQ(run.with.segments.size(), 2u);
        EXPECT_EQ(run.with.fdi.outcome, Outcome::kRight) << what;
        EXPECT_LT(run.with.segments[1].max_deg, run.with.bound_deg) << what;
        if (stuck) continue;
        EXPECT_GT(run.without.segments[1].max_deg, run.with.segments[1].max_deg) << what;
        if (!star_tracker) {
          EXPECT_GT(run.without.segments[1].max_deg, run.without.bound_deg) << what;
        }
      }
    }
  }
}

TEST(ClosedLoop, SameSeedSameRunBitForBit) {
  Scenario sc = read_scenario(test::source_path("examples/sim/closed_loop_nadir.yaml")).value();
  sc.duration_s = 1900.0;  // past the example's fault (a fault after the end of the run is an error)
  std::vector<double> errors[2];
  for (auto& errors_of_run : errors) {
    auto sim = ClosedLoopSimulator::create(sc, {}).value();
    auto estimator = PipelineEstimator::create(sc.unit, {}, sim.initial_q_NB()).value();
    const ClosedLoopRecord record = run_closed_loop(sim, estimator).value();
    for (const PointingSample& s : record.series) errors_of_run.push_back(s.error_deg);
  }
  EXPECT_EQ(errors[0], errors[1]);
}

// The example specs: the in-process one (520 runs) and the DDS one (26 runs, domain 0).
TEST(CampaignSpec, ExamplesReadWithTheirTargets) {
  const auto local = read_campaign_spec(test::source_path("examples/campaign.yaml"));
  ASSERT_TRUE(local) << local.error().message;
  EXPECT_EQ(local->target, CampaignTarget::kInProcess);
  EXPECT_EQ(local->loop, CampaignLoop::kClosed);
  EXPECT_EQ(campaign_run_count(*local).value(), 520u);
  const auto wire = read_campaign_spec(test::source_path("examples/campaign_dds.yaml"));
  ASSERT_TRUE(wire) << wire.error().message;
  EXPECT_EQ(wire->target, CampaignTarget::kDds);
  EXPECT_EQ(wire->dds_domain, 0);
  EXPECT_EQ(campaign_run_count(*wire).value(), 26u);
}

// A service configured with pipeline_yaml_from starts from the very initial attitude (every bit) and
// keeps the spec's other keys.
TEST(CampaignSpec, ServicePipelineKeepsTheInitialAttitudeExactly) {
  test::TempDir dir;
  test::write_file(dir.file("spec.yaml"),
                   "scenarios: [orbit]\nloop: open\nkinds: [stuck]\ngyros: [1]\n"
                   "onsets_s: [60]\nseeds: [1]\npipeline: {exclusion_enabled: false}\n");
  const auto spec = read_campaign_spec(dir.file("spec.yaml"));
  ASSERT_TRUE(spec) << spec.error().message;
  const Quaternion q = canonical(quat_exp(Eigen::Vector3d(0.1, -0.2, 0.3)));
  test::write_file(dir.file("service.yaml"), "pipeline:\n  " + pipeline_yaml_from(*spec, q) + "\n");
  const auto config = fdi::read_pipeline_config(dir.file("service.yaml"));
  ASSERT_TRUE(config) << config.error().message;
  EXPECT_EQ(config->initial_q_RB.coeffs(), q.coeffs());
  EXPECT_FALSE(config->exclusion_enabled);
}

// Cases are made on demand (index → case) in the documented order: scenario, fault-free runs, kind, gyro,
// onset, size, seed, checked against the nested loops that order describes.
TEST(CampaignSpec, CasesAreMadeOnDemandInTheFixedOrder) {
  test::TempDir dir;
  test::write_file(
      dir.file("spec.yaml"),
      "loop: open\nscenarios: [orbit, slews]\nkinds: [bias, stuck]\nsizes: {bias: [0.01, 0.02]}\n"
      "gyros: [2, 1]\nonsets_s: [60, 30]\nseeds: [7, 3]\nfault_free: true\n");
  const auto spec = read_campaign_spec(dir.file("spec.yaml"));
  ASSERT_TRUE(spec) << spec.error().message;
  std::vector<CampaignCase> expected;
  for (std::size_t s = 0; s < 2; ++s) {
    for (std::uint64_t seed : {7u, 3u}) expected.push_back({expected.size(), s, std::nullopt, seed, {}});
    for (FaultKind kind : {FaultKind::kBias, FaultKind::kStuck}) {
      for (int gyro : {2, 1}) {
        for (double onset : {60.0, 30.0}) {
          for (double size :
               kind == FaultKind::kBias ? std::vector<double>{0.01, 0.02} : std::vector<double>{0.0}) {
            for (std::uint64_t seed : {7u, 3u}) {
              FaultSpec f;
              f.kind = kind;
              f.gyro = gyro;
              f.at_s = onset;
              f.size = size;
              expected.push_back({expected.size(), s, f, seed, {}});
            }
          }
        }
      }
    }
  }
  ASSERT_EQ(campaign_run_count(*spec).value(), expected.size());  // 2 × (2 + 2·2·2·2 + 2·2·1·2) = 52
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const CampaignCase c = campaign_case(*spec, i);
    EXPECT_EQ(c.index, i);
    EXPECT_EQ(c.scenario, expected[i].scenario) << i;
    EXPECT_EQ(c.seed, expected[i].seed) << i;
    ASSERT_EQ(c.fault.has_value(), expected[i].fault.has_value()) << i;
    if (!c.fault) continue;
    EXPECT_EQ(format_fault_spec(*c.fault), format_fault_spec(*expected[i].fault)) << i;
  }
}

// A small spec describing an enormous matrix (20,000 onsets × 20,000 seeds: 218 KB) is refused before any
// case exists, naming the lists and the product; the count itself never overflows.
TEST(CampaignSpec, HugeMatrixIsRefusedBeforeExpansion) {
  test::TempDir dir;
  std::string onsets, seeds;
  for (int i = 0; i < 20000; ++i) {
    onsets += (i ? ", " : "") + std::to_string(i + 1);
    seeds += (i ? ", " : "") + std::to_string(i);
  }
  test::write_file(dir.file("big.yaml"),
                   "loop: open\nscenarios: [orbit]\nkinds: [stuck]\ngyros: [1]\nonsets_s: [" + onsets +
                       "]\nseeds: [" + seeds + "]\nduration_s: 30000\n");
  const auto big = read_campaign_spec(dir.file("big.yaml"));
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().message.find(dir.file("big.yaml") + ": the matrix has 400000000 runs ("), 0u)
      << big.error().message;
  for (const char* needle : {"onsets_s 20000", "seeds 20000", "more than 1000000"})
    EXPECT_NE(big.error().message.find(needle), std::string::npos) << big.error().message;
  // Far beyond 2^64 with a few lists (built in memory): still an error with the exact count, no wrap-around.
  CampaignSpec spec;
  spec.scenarios.resize(3);
  spec.kinds = {FaultKind::kBias};
  spec.gyros = {1, 2, 3, 4};
  spec.onsets_s.resize(1'000'000);
  spec.seeds.resize(1'000'000);
  spec.sizes = {{FaultKind::kBias, std::vector<double>(1'000'000)}};
  spec.fault_free = true;
  const auto huge = campaign_run_count(spec);
  ASSERT_FALSE(huge);
  EXPECT_NE(huge.error().message.find("1.2e+19 runs"), std::string::npos) << huge.error().message;
  spec.onsets_s.resize(10);
  spec.seeds.resize(10);
  spec.sizes[0].second.resize(10);
  EXPECT_EQ(campaign_run_count(spec).value(), 3u * (10u + 4u * 10u * 10u * 10u));
}

// Every value of a spec is checked up front, its key named, its line given; nothing runs.
TEST(CampaignSpec, EveryValueIsCheckedNamingTheKey) {
  test::TempDir dir;
  const std::string head = "loop: open\nscenarios: [orbit]\n";
  const std::string rest = "gyros: [1]\nonsets_s: [60]\nseeds: [1]\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {head + "kinds: [stuck]\ngyros: [1]\nonsets_s: [.nan]\nseeds: [1]\n",
       "c.yaml:5: onsets_s[0]: '.nan' is not a number"},
      {head + "kinds: [stuck]\ngyros: [1]\nonsets_s: [-10]\nseeds: [1]\n",
       "c.yaml:5: onsets_s[0]: must not be negative"},
      {head + "kinds: [bias]\nsizes: {bias: [.nan]}\n" + rest,
       "c.yaml:4: sizes.bias[0]: '.nan' is not a number"},
      {head + "kinds: [bias]\nsizes: {bias: [1e309]}\n" + rest, "c.yaml:4: sizes.bias[0]: "},
      {head + "kinds: [noise]\nsizes: {noise: [-2]}\n" + rest,
       "c.yaml:4: sizes.noise[0]: a noise multiplier"},
      {head + "kinds: [stuck]\nsizes: {bias: [0.01]}\n" + rest,
       "c.yaml:4: sizes.bias: kind bias is not in kinds"},
      {head + "kinds: [stuck]\nsizes: {stuck: [1]}\n" + rest,
       "c.yaml:4: sizes.stuck: kind stuck takes no size"},
      {head + "kinds: [stuck]\ngyros: [1, 1]\nonsets_s: [60]\nseeds: [1]\n",
       "c.yaml:4: gyros[1]: the same value as gyros[0]"},
      {head + "kinds: [stuck, stuck]\n" + rest, "c.yaml:3: kinds[1]: the same value as kinds[0]"},
      {head + "kinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [-1]\n",
       "c.yaml:6: seeds[0]: expected a whole number from 0 to 18446744073709551615, got '-1'"},
      {head + "kinds: [stuck]\n" + rest + "fault_free: maybe\n",
       "c.yaml:7: fault_free: expected true or false, got 'maybe'"},
      {head + "kinds: [stuck]\ngyros: [1.5]\nonsets_s: [60]\nseeds: [1]\n",
       "c.yaml:4: gyros[0]: expected a whole number from 1 to 32, got '1.5'"},
      {head + "kinds: [stuck]\ngyros: [5]\nonsets_s: [60]\nseeds: [1]\n",
       "c.yaml:4: gyros[0]: gyro 5 does not exist in scenarios[0] (orbit)"},
      {head + "kinds: [stuck]\ngyros: [1]\nonsets_s: [60, 7000]\nseeds: [1]\n",
       "c.yaml:5: onsets_s[1]: 7000 s is at or after the end of scenarios[0] (orbit) (6000 s)"},
      {head + "kinds: [stuck]\n" + rest + "duration_s: 1e300\n",
       "c.yaml:7: duration_s: with scenarios[0] (orbit): duration_s must be above 0 and at most 6e+08 s"},
      {head + "kinds: [stuck]\n" + rest + "duration_s: 30\n",
       "c.yaml:5: onsets_s[0]: 60 s is at or after the end of scenarios[0] (orbit) (30 s, duration_s)"},
      {"loop: [open]\nscenarios: [orbit]\nkinds: [stuck]\n" + rest, "c.yaml:1: loop: expected a text value"},
      {head + "kinds: [stuck]\n" + rest + "target: dds\ndomain: 999\n",
       "c.yaml:8: domain: expected a whole number from 0 to 232, got '999'"},
      {head + "kinds: [stuck]\n" + rest + "seeds: [2]\n", "key 'seeds' appears twice"},
  };
  for (const auto& [text, needle] : bad) {
    test::write_file(dir.file("c.yaml"), text);
    const auto spec = read_campaign_spec(dir.file("c.yaml"));
    ASSERT_FALSE(spec) << text;
    EXPECT_NE(spec.error().message.find(needle), std::string::npos) << text << " -> " << spec.error().message;
  }
}

// A scenario whose unit the pipeline cannot fuse (coplanar axes) is read, and each of its runs is an
// error naming why (a row with outcome error: CampaignRunner.*), not the end of the campaign; a noise
// fault on a gyro without white noise is refused before the campaign starts, naming the case.
TEST(CampaignSpec, ImpossibleCasesAreErrorsOrRefusedUpFront) {
  test::TempDir dir;
  test::write_file(
      dir.file("flat.yaml"),
      "unit: flat\ngyros:\n"
      "  - {id: 1, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [1, 0, 0], noise: {arw_dps_rtHz: 3e-5}}\n"
      "  - {id: 2, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [0, 1, 0], noise: {arw_dps_rtHz: 3e-5}}\n"
      "  - {id: 3, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [0.6, 0.8, 0], noise: {arw_dps_rtHz: "
      "3e-5}}\n"
      "  - {id: 4, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [0.8, -0.6, 0]}\n");
  test::write_file(dir.file("flat_orbit.yaml"), "scenario: orbit\nunit: flat.yaml\n");
  test::write_file(dir.file("c.yaml"),
                   "loop: open\nscenarios: [orbit, flat_orbit.yaml]\nkinds: [stuck]\n"
                   "gyros: [1]\nonsets_s: [60]\nseeds: [1]\n");
  const auto flat = read_campaign_spec(dir.file("c.yaml"));
  ASSERT_TRUE(flat) << flat.error().message;
  const auto run = run_campaign_case(*flat, campaign_case(*flat, 1));  // flat_orbit.yaml, stuck gyro 1
  ASSERT_FALSE(run);
  EXPECT_EQ(run.error().message,
            "the fusion pipeline cannot run this unit: geometry: the gyro axes do not span three dimensions");
  // Gyro 1 without white noise: a noise fault on it has nothing to multiply.
  test::write_file(
      dir.file("quiet.yaml"),
      "unit: quiet\ngyros:\n"
      "  - {id: 1, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [1, 0, 0]}\n"
      "  - {id: 2, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [0, 1, 0], noise: {arw_dps_rtHz: 3e-5}}\n"
      "  - {id: 3, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [0, 0, 1], noise: {arw_dps_rtHz: 3e-5}}\n"
      "  - {id: 4, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: [0.6, 0.8, 0], noise: {arw_dps_rtHz: "
      "3e-5}}\n");
  test::write_file(dir.file("quiet_orbit.yaml"), "scenario: orbit\nunit: quiet.yaml\n");
  test::write_file(dir.file("n.yaml"),
                   "loop: open\nscenarios: [quiet_orbit.yaml]\nkinds: [stuck, noise]\n"
                   "sizes: {noise: [10]}\ngyros: [2, 1]\nonsets_s: [60]\nseeds: [1]\n");
  const auto quiet = read_campaign_spec(dir.file("n.yaml"));
  ASSERT_FALSE(quiet);
  EXPECT_NE(quiet.error().message.find("n.yaml:3: kinds[1]: cannot run on gyro 1 of scenarios[0] ("),
            std::string::npos)
      << quiet.error().message;
  EXPECT_NE(quiet.error().message.find("has no white noise"), std::string::npos) << quiet.error().message;
}

// A run that did not finish is a row of its own: the case's columns, outcome error, the result columns
// empty and the message in `error` on one CSV line (commas and line breaks replaced), read back as such.
TEST(CampaignSpec, ErrorRowsRoundTripOnOneLine) {
  test::TempDir dir;
  test::write_file(dir.file("c.yaml"),
                   "loop: open\nscenarios: [orbit]\nkinds: [stuck]\ngyros: [1]\n"
                   "onsets_s: [60]\nseeds: [7]\nfault_free: true\n");
  const auto spec = read_campaign_spec(dir.file("c.yaml"));
  ASSERT_TRUE(spec) << spec.error().message;
  const std::string text = campaign_csv_row(campaign_error_row(*spec, 1, "bad, worse\nworst"));
  EXPECT_EQ(text, "1,orbit,stuck,1,60,0,7,error,,,,,,,,,,,,,,,,,bad; worse worst");
  const auto row = parse_campaign_row(text);
  ASSERT_TRUE(row) << row.error().message;
  EXPECT_EQ(row->run, 1u);
  EXPECT_EQ(row->kind, "stuck");
  EXPECT_EQ(row->seed, 7u);
  EXPECT_EQ(row->error, "bad; worse worst");
  EXPECT_EQ(campaign_csv_row(*row), text);
  EXPECT_FALSE(parse_campaign_row("1,orbit,stuck,1,60,0,7,error,,,,,,,,,,,,,,,,,"));  // no message
  // A finished run's row: `error` empty (the line ends with its comma), not an error when read back.
  EXPECT_EQ(campaign_csv_header().substr(campaign_csv_header().rfind(',')), ",error");
}

// Inertia, torques and momenta out of their stated ranges are refused naming the key and its line.
TEST(ClosedLoopScenario, RangesNameTheKey) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"  inertia_kg_m2: [1e-300, 1e-300, 1e-300]\n",
       "x.yaml:3: closed_loop: inertia_kg_m2 principal moments must be from 1e-04 to 1e+09"},
      {"  inertia_kg_m2: [1e300, 1e300, 1e300]\n",
       "inertia_kg_m2 principal moments must be from 1e-04 to 1e+09"},
      {"  inertia_kg_m2: [1, 1, 5]\n", "break the triangle inequality"},
      {"  inertia_kg_m2: [[10, 1, 0], [0, 10, 0], [0, 0, 10]]\n", "inertia_kg_m2 must be symmetric"},
      {"  inertia_kg_m2: [[10, 0, 0], [0, -10, 0], [0, 0, 10]]\n", "inertia_kg_m2 must be positive definite"},
      {"  disturbance: {constant_Nm: [1e300, 0, 0]}\n",
       "disturbance.constant_Nm[0] must be from -1000 to 1000"},
      {"  disturbance: {periodic_Nm: [0, 0, -2e3]}\n",
       "disturbance.periodic_Nm[2] must be from -1000 to 1000"},
      {"  wheels: {max_momentum_Nms: 1e300}\n", "wheels.max_momentum_Nms must be above 0 and at most 1e+05"},
      {"  wheels: {max_torque_Nm: 0}\n", "wheels.max_torque_Nm must be above 0"},
      {"  controller: {bandwidth_hz: 1e300}\n", "controller.bandwidth_hz must be above 0 and at most 100"},
      {"  initial_rate_error_dps: [1e300, 0, 0]\n",
       "initial_rate_error_dps (its norm) must be from 0 to 360"},
  };
  for (const auto& [text, needle] : bad) {
    const auto r = parse_scenario("scenario: orbit\nclosed_loop:\n" + text, "x.yaml");
    ASSERT_FALSE(r) << text;
    EXPECT_NE(r.error().message.find(needle), std::string::npos) << text << " -> " << r.error().message;
  }
}

// An estimate that is not a number steers the spacecraft into a state that is not one: the run fails
// with a clear message instead of summarizing NaN as a pointing error of 0.
TEST(ClosedLoop, NonFiniteStateFailsTheRun) {
  class NanEstimator final : public Estimator {
   public:
    Result<EstimatorOutput> estimate(const SimEpoch& epoch) override {
      EstimatorOutput out;
      fdi::AttitudeEstimate e;
      e.stamp_ns = epoch.stamp_ns;
      e.q_RB = Quaternion(NAN, NAN, NAN, NAN);
      e.omega_BR_B_rad_s = Eigen::Vector3d::Constant(NAN);
      out.latest = e;
      return out;
    }
  };
  auto sim = ClosedLoopSimulator::create(loop_scenario(quiet_spec(), 10.0), {}).value();
  NanEstimator estimator;
  const auto record = run_closed_loop(sim, estimator);
  ASSERT_FALSE(record);
  EXPECT_NE(record.error().message.find("closed loop: the spacecraft's state is not finite at t = "),
            std::string::npos)
      << record.error().message;
}

TEST(ClosedLoopScenario, BadKeysNameTheLine) {
  const auto bad = parse_scenario("scenario: orbit\nclosed_loop:\n  wheels: {count: 5}\n", "x.yaml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("x.yaml:3"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("count"), std::string::npos) << bad.error().message;
  const auto not_orbit = parse_scenario("scenario: static\nclosed_loop: {}\n", "y.yaml");
  ASSERT_FALSE(not_orbit);
  EXPECT_NE(not_orbit.error().message.find("orbit"), std::string::npos);
}

}  // namespace
}  // namespace tetra::sim
