#pragma once
// Attitude rows (docs/interfaces.md §2.4) as `tetra replay --attitude` and `tetra record --attitude` write
// them: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros

#include <string>

#include "tetra/core/geometry.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::cli {

inline constexpr const char* kAttitudeHeader =
    "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros\n";

//! Appends one row stamped `time_s` [s] (numbers in shortest round-trip form). sigma_deg is the 1σ of the
//! total error angle (norm of the per-axis 1σ).
//! The `gyros` cell: the ids of the gyros used, as digits ("124") for N ≤ 9 and separated by ';'
//! ("1;2;10") for N ≥ 10, so the cell is one CSV field for any N.
std::string gyros_cell(GyroMask mask, int n_gyros);

void append_attitude_row(std::string& out, double time_s, const fdi::AttitudeEstimate& attitude, int n_gyros);

}  // namespace tetra::cli
