#pragma once
// Attitude rows (INTERFACES §2.4) as `tetra replay --attitude` and `tetra record --attitude` write them:
// time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros

#include <string>

#include "tetra/fdi/types.hpp"

namespace tetra::cli {

inline constexpr const char* kAttitudeHeader =
    "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros\n";

//! Appends one row stamped `time_s` [s] (numbers in shortest round-trip form). sigma_deg is the 1σ of the
//! total error angle (norm of the per-axis 1σ).
void append_attitude_row(std::string& out, double time_s, const fdi::AttitudeEstimate& attitude, int n_gyros);

}  // namespace tetra::cli
