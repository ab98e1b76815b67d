#pragma once
// Frames for ground tests (docs/interfaces.md §1).
//   B: body frame, the unit's analytical trihedron XYZ (gyro 4 along +X).
//   L: lab frame, X up, Y east, Z north.
// Two-axis turntable: inner axis = body X; C_LB = R_y(outer) · R_x(inner) (active, right-handed).

#include <Eigen/Core>

namespace tetra {

//! [rad/s] Earth rotation vector in the lab frame L at geodetic latitude `latitude_rad`:
//! Ω·(sin φ, 0, cos φ).
Eigen::Vector3d earth_rate_L(double latitude_rad);

//! Active rotation about X by `angle_rad`.
Eigen::Matrix3d rotation_x(double angle_rad);
//! Active rotation about Y by `angle_rad`.
Eigen::Matrix3d rotation_y(double angle_rad);

//! DCM body → lab of the two-axis table at encoder angles (inner, outer) [rad]: v_L = C_LB · v_B.
Eigen::Matrix3d turntable_C_LB(double inner_rad, double outer_rad);

//! [rad/s] Body rate (in B) produced by the table's gimbal rates, excluding the Earth rate:
//! ω_B = (inner_dot, outer_dot·cos(inner), −outer_dot·sin(inner)).
Eigen::Vector3d turntable_rate_B(double inner_rad, double inner_dot_rad_s, double outer_dot_rad_s);

//! [rad/s] Earth rate seen in B at the table's encoder angles: C_LBᵀ · ω_e^L.
Eigen::Vector3d turntable_earth_rate_B(double inner_rad, double outer_rad, double latitude_rad);

}  // namespace tetra
