#pragma once
// Attitude rows (INTERFACES §2.4) as `tetra record --attitude` writes them:
// time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros

#include <string>

#include "tetra/fdi/types.hpp"

namespace tetra::cli {

inline constexpr const char* kAttitudeHeader =
    "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros\n";

//! Appends one row (numbers in shortest round-trip form). sigma_deg is the 1σ of the total error angle (norm
//! of the per-axis 1σ), as `tetra replay` writes it.
void append_attitude_row(std::string& out, const fdi::AttitudeEstimate& attitude, int n_gyros);

}  // namespace tetra::cli
