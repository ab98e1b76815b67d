#pragma once
// Attitude rows (docs/interfaces.md §2.4) as `tetra replay --attitude` and `tetra record --attitude` write
// them: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros, then the attitude filter's
// sigma_x_deg,sigma_y_deg,sigma_z_deg (1σ per body axis) and bias_1_dps..bias_N_dps (each gyro's bias
// estimate).

#include <string>

#include "tetra/core/geometry.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::cli {

//! The header line (with its newline) for `n_gyros` gyros: the 11 columns every reader knows, then the
//! filter's columns.
std::string attitude_header(int n_gyros);

//! Appends one row stamped `time_s` [s] (numbers in shortest round-trip form). sigma_deg is the 1σ of the
//! total error angle (norm of the per-axis 1σ). A bias the estimate does not carry (a size other than N, as
//! from a recorder that has no filter) is written `nan`.
//! The `gyros` cell: the ids of the gyros used, as digits ("124") for N ≤ 9 and separated by ';'
//! ("1;2;10") for N ≥ 10, so the cell is one CSV field for any N.
std::string gyros_cell(GyroMask mask, int n_gyros);

void append_attitude_row(std::string& out, double time_s, const fdi::AttitudeEstimate& attitude, int n_gyros);

}  // namespace tetra::cli
