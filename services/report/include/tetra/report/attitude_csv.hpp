#pragma once
// Attitude rows (docs/interfaces.md §2.4) as `tetra replay --attitude` and `tetra record --attitude` write
// them: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros, then the attitude filter's
// sigma_x_deg,sigma_y_deg,sigma_z_deg (1σ per body axis) and bias_1_dps..bias_N_dps (each gyro's bias
// estimate).

#include <cstddef>
#include <span>
#include <string>
#include <string_view>

#include "tetra/core/geometry.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::report {

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

//! The most bytes one row of `n_gyros` gyros takes (newline included).
std::size_t attitude_row_max_bytes(int n_gyros);
//! The row append_attitude_row appends, written at `out` (room for attitude_row_max_bytes), with
//! `bias_rad_s` for the estimate's biases (written nan unless it holds N) and `gyros` (gyros_cell of the
//! estimate's mask) as its gyros cell; returns the row's end. For a writer that formats rows straight
//! into a buffer of its own.
char* format_attitude_row(char* out, double time_s, const fdi::AttitudeEstimate& attitude,
                          std::span<const double> bias_rad_s, int n_gyros, std::string_view gyros);

//! gyros_cell of the last mask asked for, made again only when the mask changes (it seldom does).
class GyrosCellCache {
 public:
  explicit GyrosCellCache(int n_gyros) : n_gyros_(n_gyros) {}
  const std::string& cell(GyroMask mask);

 private:
  int n_gyros_;
  GyroMask mask_ = 0;
  bool valid_ = false;
  std::string cell_;
};

}  // namespace tetra::report
