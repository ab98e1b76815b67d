#pragma once
// Truth motion of the simulator, in closed form (no numerical integration anywhere).
//
// The attitude is a product of rotations, each about a fixed axis of its own frame by a known
// angle φ_k(t) with known rate φ̇_k(t):
//   q_RB(t) = q_0 ⊗ exp(φ_1 a_1) ⊗ exp(φ_2 a_2) ⊗ …
// and the body rate relative to R follows exactly from the chain: ω_k = R_kᵀ ω_{k−1} + φ̇_k a_k.
// For a constant rate this is the exact closed form q(t) = exp(ω t).
//
// Scenarios and frames (documented again in docs/sim.md):
//   static     R = lab frame L (X up, Y east, Z north); B = L (the table at encoder zero);
//              the gyros sense the Earth rate only.
//   lab-orbit  R = L; the outer gimbal turns the unit about body +Y at `pitch_rate_dps`
//              (seed: 0.06 deg/s, one turn in 100 min); q_LB(t) = exp(ω t ŷ); Earth rate sensed.
//   orbit      R = an inertial frame I equal to the orbit (LVLH) frame O at t = 0
//              (O: X along velocity, Y = −orbit normal, Z nadir). O turns about its −Y axis at
//              n = 360°/period relative to I, so the geo-pointing body pitches about body −Y at n
//              (the pitch gyro reads −0.06 deg/s for a 100-min orbit). No Earth rate: the gyros
//              sense ω_B relative to I.
//              Attitude-control motion (ACS): B deviates from O by 3-2-1 Euler angles (yaw ψ,
//              pitch θ, roll φ), each a sum of two sinusoids
//                 e(t) = A/2·[sin(w₁t + p₁) + sin(w₂t + p₂)],  w₂ = 0.618·w₁,
//                 w₁ = √(2·α / (A·(1 + 0.618²)))
//              with seeded phases, so |e| ≤ A (amplitude) and |ë| ≤ α (peak Euler-angle
//              acceleration): both are parameters and echoed in the log's metadata.
//   slews      orbit, then rest-to-rest slews about body axes: angle Φ over duration T with the
//              cycloidal profile φ(u) = Φ·(u − sin(2πu)/(2π)), u = (t − start)/T: zero rate and zero
//              acceleration at both ends, peak rate 2Φ/T, peak acceleration 2πΦ/T².

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"

namespace tetra::sim {

enum class MotionKind { kStatic, kLabOrbit, kOrbit, kSlews };

//! Attitude-control motion of `orbit` and `slews`: amplitude 0 switches it off.
struct AcsMotion {
  double amplitude_deg = 0.05;      //!< [deg] bound of each Euler angle's deviation
  double peak_accel_dps2 = 1.0e-5;  //!< [deg/s²] bound of each Euler angle's acceleration
};

//! One rest-to-rest slew about a body axis.
struct Slew {
  Eigen::Vector3d axis_B = Eigen::Vector3d::UnitX();  //!< unit axis in B
  double angle_deg = 30.0;                            //!< [deg] signed angle
  double start_s = 0.0;                               //!< [s]
  double duration_s = 120.0;                          //!< [s]
};

struct MotionSpec {
  MotionKind kind = MotionKind::kStatic;
  double latitude_deg = -23.2;     //!< [deg] static, lab-orbit: geodetic latitude of the lab
  double pitch_rate_dps = 0.06;    //!< [deg/s] lab-orbit: outer gimbal rate (about body +Y)
  double orbit_period_s = 6000.0;  //!< [s] orbit, slews: one pitch revolution
  AcsMotion acs;                   //!< orbit, slews
  std::vector<Slew> slews;         //!< slews
};

//! Ranges of the motion's parameters (docs/sim.md, "Ranges"): beyond them the motion is not a physical
//! one (or not representable in doubles: an orbit period of 1e-298 s turns every number into NaN).
inline constexpr double kMaxPitchRate_dps = 1000.0;   //!< [deg/s] |pitch_rate_dps|
inline constexpr double kMinOrbitPeriod_s = 1200.0;   //!< [s] 20 min (the lowest Earth orbit takes ~87 min)
inline constexpr double kMaxOrbitPeriod_s = 6.0e7;    //!< [s] 1e6 min (about 1.9 years)
inline constexpr double kMaxAcsAmplitude_deg = 45.0;  //!< [deg] an attitude-control deviation, not a slew
inline constexpr double kMaxAcsAccel_dps2 = 100.0;    //!< [deg/s²]
inline constexpr double kMaxSlewAngle_deg = 3600.0;   //!< [deg] |angle_deg| of one slew (10 turns)

//! Checks the spec against the ranges above; errors name the scenario file's key.
Status validate_motion(const MotionSpec& spec);

//! Truth at one instant.
struct MotionState {
  Quaternion q_RB;                   //!< body → reference frame R (see above), unit norm
  Eigen::Vector3d omega_BR_B_rad_s;  //!< [rad/s] rate of B relative to R, in B (dq/dt = ½ q ⊗ ω)
  Eigen::Vector3d omega_BN_B_rad_s;  //!< [rad/s] inertial rate of B, in B: what the gyros sense
};

//! Evaluates the truth motion at any time. Immutable once created; thread-safe to evaluate.
class TruthMotion {
 public:
  //! Validates the spec; `seed` draws the ACS phases.
  static Result<TruthMotion> create(const MotionSpec& spec, std::uint64_t seed);

  MotionState at(double t_s) const;

  const MotionSpec& spec() const { return spec_; }
  //! Name of the reference frame R ("lab" or "inertial").
  std::string reference_frame() const;
  //! [deg] actual bound of the ACS Euler angles (= amplitude) and [deg/s²] of their accelerations.
  double acs_peak_accel_dps2() const;

 private:
  MotionSpec spec_;
  Eigen::Vector3d earth_rate_L_rad_s_ = Eigen::Vector3d::Zero();
  double acs_w1_rad_s_ = 0.0;
  double acs_w2_rad_s_ = 0.0;
  double acs_phase_rad_[3][2] = {};  //!< per Euler angle (yaw, pitch, roll), per sinusoid
};

//! Names of the built-in motion kinds, as used on the command line.
std::string_view motion_kind_name(MotionKind kind);

}  // namespace tetra::sim
