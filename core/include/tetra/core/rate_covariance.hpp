#pragma once
// Covariance of a body rate estimated by weighted least squares from single-axis gyros.

#include <optional>
#include <span>

#include <Eigen/Core>

namespace tetra {

//! (Σ_i h_i h_iᵀ / σ_i²)⁻¹ for gyros with unit axes `axes_B` and independent noise `sigmas` (any one unit:
//! the result is in its square), made exactly symmetric. Fewer than 3 gyros, or axes that do not span
//! 3-D: nullopt. The sizes of the spans must agree.
std::optional<Eigen::Matrix3d> least_squares_rate_covariance(std::span<const Eigen::Vector3d> axes_B,
                                                             std::span<const double> sigmas);

}  // namespace tetra
