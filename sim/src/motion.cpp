#include "tetra/sim/motion.hpp"

#include <algorithm>
#include <cmath>

#include "ranges.hpp"
#include "tetra/core/frames.hpp"
#include "tetra/core/units.hpp"
#include "tetra/sim/random.hpp"

namespace tetra::sim {

namespace {

constexpr double kAcsFrequencyRatio = 0.618;  // w₂/w₁: incommensurate, so the motion does not repeat soon

//! Accumulates a chain of rotations about fixed axes of their own frames.
struct Chain {
  Quaternion q = Quaternion::Identity();
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();  // [rad/s] rate of the chain's last frame relative to R

  void rotate(const Eigen::Vector3d& axis, double angle_rad, double rate_rad_s) {
    const Quaternion step = quat_exp(axis * angle_rad);
    q = q * step;
    omega = step.conjugate() * omega + axis * rate_rad_s;
  }
};

}  // namespace

std::string_view motion_kind_name(MotionKind kind) {
  switch (kind) {
    case MotionKind::kStatic:
      return "static";
    case MotionKind::kLabOrbit:
      return "lab-orbit";
    case MotionKind::kOrbit:
      return "orbit";
    case MotionKind::kSlews:
      return "slews";
  }
  return "unknown";
}

Status validate_motion(const MotionSpec& spec) {
  if (Status st = check_range("latitude_deg", spec.latitude_deg, -90.0, 90.0, "deg"); !st) return st;
  if (Status st =
          check_range("pitch_rate_dps", spec.pitch_rate_dps, -kMaxPitchRate_dps, kMaxPitchRate_dps, "deg/s");
      !st)
    return st;
  if (Status st =
          check_range("orbit_period_s", spec.orbit_period_s, kMinOrbitPeriod_s, kMaxOrbitPeriod_s, "s");
      !st)
    return st;
  if (Status st = check_range("acs.amplitude_deg", spec.acs.amplitude_deg, 0.0, kMaxAcsAmplitude_deg, "deg");
      !st)
    return st;
  if (spec.acs.amplitude_deg > 0.0) {
    if (Status st = check_range("acs.peak_accel_dps2", spec.acs.peak_accel_dps2, 0.0, kMaxAcsAccel_dps2,
                                "deg/s^2", true);
        !st)
      return st;
  }
  for (std::size_t i = 0; i < spec.slews.size(); ++i) {
    const Slew& s = spec.slews[i];
    const std::string where = "slews[" + std::to_string(i) + "].";
    if (!s.axis_B.allFinite() || s.axis_B.norm() < 1e-9)
      return bad_input(where + "axis must be a non-zero vector");
    if (Status st =
            check_range(where + "angle_deg", s.angle_deg, -kMaxSlewAngle_deg, kMaxSlewAngle_deg, "deg");
        !st)
      return st;
    if (!std::isfinite(s.start_s)) return bad_input(where + "start_s must be finite");
    if (!std::isfinite(s.duration_s) || s.duration_s <= 0.0)
      return bad_input(where + "duration_s must be positive");
  }
  return ok_status();
}

Result<TruthMotion> TruthMotion::create(const MotionSpec& spec, std::uint64_t seed) {
  if (Status st = validate_motion(spec); !st) return bad_input("motion: " + st.error().message);
  TruthMotion m;
  m.spec_ = spec;
  for (Slew& s : m.spec_.slews) s.axis_B.normalize();
  m.earth_rate_L_rad_s_ = earth_rate_L(spec.latitude_deg * kDegToRad);
  if (spec.acs.amplitude_deg > 0.0) {
    const double a_rad = spec.acs.amplitude_deg * kDegToRad;
    const double alpha_rad_s2 = spec.acs.peak_accel_dps2 * kDegToRad;
    m.acs_w1_rad_s_ =
        std::sqrt(2.0 * alpha_rad_s2 / (a_rad * (1.0 + kAcsFrequencyRatio * kAcsFrequencyRatio)));
    m.acs_w2_rad_s_ = kAcsFrequencyRatio * m.acs_w1_rad_s_;
    Rng rng(stream_seed(seed, Stream::kMotion, -1));
    for (auto& axis : m.acs_phase_rad_) {
      for (double& phase : axis) phase = 2.0 * kPi * rng.uniform();
    }
  }
  return m;
}

std::string TruthMotion::reference_frame() const {
  return (spec_.kind == MotionKind::kStatic || spec_.kind == MotionKind::kLabOrbit) ? "lab" : "inertial";
}

double TruthMotion::acs_peak_accel_dps2() const {
  if (spec_.acs.amplitude_deg <= 0.0) return 0.0;
  const double a = spec_.acs.amplitude_deg / 2.0;
  return a * (acs_w1_rad_s_ * acs_w1_rad_s_ + acs_w2_rad_s_ * acs_w2_rad_s_);
}

MotionState TruthMotion::at(double t_s) const {
  Chain chain;
  MotionState state;
  switch (spec_.kind) {
    case MotionKind::kStatic:
    case MotionKind::kLabOrbit: {
      if (spec_.kind == MotionKind::kLabOrbit) {
        const double rate = spec_.pitch_rate_dps * kDegToRad;
        chain.rotate(Eigen::Vector3d::UnitY(), rate * t_s, rate);
      }
      state.q_RB = chain.q;
      state.omega_BR_B_rad_s = chain.omega;
      state.omega_BN_B_rad_s = chain.omega + chain.q.conjugate() * earth_rate_L_rad_s_;
      return state;
    }
    case MotionKind::kOrbit:
    case MotionKind::kSlews: {
      const double n = 2.0 * kPi / spec_.orbit_period_s;
      chain.rotate(-Eigen::Vector3d::UnitY(), n * t_s, n);  // O relative to I
      if (spec_.acs.amplitude_deg > 0.0) {
        const double half = spec_.acs.amplitude_deg * kDegToRad / 2.0;
        const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(),
                                         Eigen::Vector3d::UnitX()};  // 3-2-1
        for (int k = 0; k < 3; ++k) {
          const double x1 = acs_w1_rad_s_ * t_s + acs_phase_rad_[k][0];
          const double x2 = acs_w2_rad_s_ * t_s + acs_phase_rad_[k][1];
          const double angle = half * (std::sin(x1) + std::sin(x2));
          const double rate = half * (acs_w1_rad_s_ * std::cos(x1) + acs_w2_rad_s_ * std::cos(x2));
          chain.rotate(axes[k], angle, rate);
        }
      }
      if (spec_.kind == MotionKind::kSlews) {
        for (const Slew& s : spec_.slews) {
          if (t_s <= s.start_s) continue;
          const double u = std::min((t_s - s.start_s) / s.duration_s, 1.0);
          const double big = s.angle_deg * kDegToRad;
          const double angle = big * (u - std::sin(2.0 * kPi * u) / (2.0 * kPi));
          const double rate = u < 1.0 ? big / s.duration_s * (1.0 - std::cos(2.0 * kPi * u)) : 0.0;
          chain.rotate(s.axis_B, angle, rate);
        }
      }
      state.q_RB = chain.q;
      state.omega_BR_B_rad_s = chain.omega;
      state.omega_BN_B_rad_s = chain.omega;
      return state;
    }
  }
  return state;
}

}  // namespace tetra::sim
