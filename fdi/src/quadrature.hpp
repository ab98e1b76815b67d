#pragma once
// Independent errors added to a 1σ per axis.

#include <Eigen/Core>

namespace tetra::fdi::detail {

//! Per axis √(a² + b²) [the unit of a and b].
inline Eigen::Vector3d root_sum_square(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (a.cwiseProduct(a) + b.cwiseProduct(b)).cwiseSqrt();
}

}  // namespace tetra::fdi::detail
