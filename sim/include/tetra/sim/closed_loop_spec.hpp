#pragma once
// What the closed-loop simulator simulates besides the gyros: the spacecraft (inertia, reaction
// wheels), the disturbance torques, the attitude controller and the pointing mode. Read from the
// `closed_loop:` map of a scenario file (docs/sim.md lists every key, its unit and its default).
//
// Frames (Basilisk's names): N inertial (= the orbit frame O at t = 0, as in the open-loop `orbit`
// scenario), O the orbit (LVLH) frame (X along the velocity, Y = −orbit normal, Z nadir; it turns
// about its −Y axis at the orbit rate n relative to N), B the body, R the commanded (reference)
// frame. q_NB maps B → N (Basilisk's σ_BN as a quaternion), ω_BN_B is the inertial body rate in B.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"

namespace YAML {
class Node;
}

namespace tetra {
class YamlReader;
}

namespace tetra::sim {

//! Reaction wheels: 3 along the body axes, or 4 in a pyramid about body +Z (azimuths 45°, 135°,
//! 225°, 315°, each axis `pyramid_elevation_deg` above the XY plane).
struct WheelSpec {
  int count = 4;                          //!< 3 or 4
  double max_torque_Nm = 0.02;            //!< [N·m] per wheel
  double max_momentum_Nms = 1.0;          //!< [N·m·s] per wheel
  double inertia_kg_m2 = 0.005;           //!< [kg·m²] wheel rotor (for the speed only)
  double pyramid_elevation_deg = 35.264;  //!< [deg] 4 wheels: axis elevation (35.264°: all axes equal)
};

//! External torques in B: constant + orbital-periodic (amplitude·sin(n·t)) + gravity gradient.
struct DisturbanceSpec {
  Eigen::Vector3d constant_Nm = Eigen::Vector3d::Zero();  //!< [N·m] in B
  Eigen::Vector3d periodic_Nm = Eigen::Vector3d::Zero();  //!< [N·m] amplitude per body axis, orbit period
  bool gravity_gradient = true;                           //!< 3n²·r̂_B × (I·r̂_B)
};

//! PD (or PID) with rate feedback on the estimated attitude and rate, per body axis:
//!   u = −I·(ω_n²·θ + 2ζω_n·δω + ω_n²/T_i·∫θ) + I·α_R + ω̂ × (I·ω̂ + H_w),  ω_n = 2π·bandwidth.
struct ControllerSpec {
  double bandwidth_hz = 0.02;  //!< [Hz] closed-loop natural frequency ω_n/2π
  double damping = 0.7;        //!< [-] ζ
  double integral_time_s = 0;  //!< [s] T_i of the integral term; 0 = PD
  double hold_after_s = 0.5;   //!< [s] attitude older than this: hold the last command
  double safe_after_s = 5.0;   //!< [s] older than this: safe mode (wheel torques zero)
};

enum class PointingMode { kInertial, kNadir };

//! A rest-to-rest slew of the commanded frame about one of its own axes, with a trapezoidal rate
//! profile bounded by the pointing's max rate and acceleration.
struct PointingSlew {
  Eigen::Vector3d axis_R = Eigen::Vector3d::UnitX();  //!< unit axis in R
  double angle_deg = 10.0;                            //!< [deg] signed
  double start_s = 0.0;                               //!< [s]
};

struct PointingSpec {
  PointingMode mode = PointingMode::kNadir;
  Quaternion q_NR0 = Quaternion::Identity();  //!< inertial: the commanded attitude R → N
  std::vector<PointingSlew> slews;            //!< offsets from the base frame, in order
  double max_rate_dps = 0.5;                  //!< [deg/s] slew rate limit
  double max_accel_dps2 = 0.02;               //!< [deg/s²] slew acceleration limit
};

struct ClosedLoopSpec {
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Vector3d(12.0, 10.0, 8.0).asDiagonal();  //!< [kg·m²] in B
  double dynamics_hz = 50.0;  //!< [Hz] RK4 step rate (the control period is split into equal steps)
  WheelSpec wheels;
  DisturbanceSpec disturbance;
  ControllerSpec controller;
  PointingSpec pointing;
  Eigen::Vector3d initial_error_deg = Eigen::Vector3d::Zero();  //!< [deg] rotation vector B from R at t=0
  Eigen::Vector3d initial_rate_error_dps = Eigen::Vector3d::Zero();  //!< [deg/s] ω_BN − ω_RN at t=0
  double pointing_bound_deg = 0.1;  //!< [deg] the stated pointing requirement (summary, recovery)
};

//! Ranges of the closed loop's numbers (docs/sim.md, "Closed loop"): a spacecraft from a 1U CubeSat
//! (~2e-3 kg·m²) to a space station (~1e8 kg·m²), its actuators and its environment.
inline constexpr double kMinInertia_kg_m2 = 1.0e-4;      //!< [kg·m²] smallest principal moment
inline constexpr double kMaxInertia_kg_m2 = 1.0e9;       //!< [kg·m²] largest principal moment
inline constexpr double kMaxWheelTorque_Nm = 1.0e3;      //!< [N·m] wheels.max_torque_Nm
inline constexpr double kMaxWheelMomentum_Nms = 1.0e5;   //!< [N·m·s] wheels.max_momentum_Nms
inline constexpr double kMaxWheelInertia_kg_m2 = 1.0e3;  //!< [kg·m²] wheels.inertia_kg_m2
inline constexpr double kMaxDisturbance_Nm = 1.0e3;      //!< [N·m] each axis of constant_Nm, periodic_Nm
inline constexpr double kMaxBandwidth_hz = 100.0;        //!< [Hz] controller.bandwidth_hz
inline constexpr double kMaxDamping = 100.0;             //!< [-] controller.damping
inline constexpr double kMaxControlTime_s = 1.0e9;       //!< [s] integral_time_s, hold_after_s, safe_after_s
inline constexpr double kMaxPointingRate_dps = 360.0;  //!< [deg/s] pointing.max_rate_dps, initial rate error
inline constexpr double kMaxPointingAccel_dps2 = 360.0;  //!< [deg/s²] pointing.max_accel_dps2
inline constexpr double kMaxPointingAngle_deg = 3600.0;  //!< [deg] |angle_deg| of one pointing slew

//! Parses the `closed_loop:` map; errors name file, line and key.
Result<ClosedLoopSpec> parse_closed_loop(const YamlReader& yaml, const YAML::Node& node);
//! Range checks; errors name the field.
Status validate_closed_loop(const ClosedLoopSpec& spec);
std::string_view pointing_mode_name(PointingMode mode);

}  // namespace tetra::sim
