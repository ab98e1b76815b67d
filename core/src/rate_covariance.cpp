#include "tetra/core/rate_covariance.hpp"

#include <Eigen/LU>

namespace tetra {

std::optional<Eigen::Matrix3d> least_squares_rate_covariance(std::span<const Eigen::Vector3d> axes_B,
                                                             std::span<const double> sigmas) {
  if (axes_B.size() < 3 || axes_B.size() != sigmas.size()) return std::nullopt;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < axes_B.size(); ++i) {
    information += axes_B[i] * axes_B[i].transpose() / (sigmas[i] * sigmas[i]);
  }
  Eigen::FullPivLU<Eigen::Matrix3d> lu(information);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Matrix3d inverse = lu.inverse();
  return 0.5 * (inverse + inverse.transpose());
}

}  // namespace tetra
