#pragma once
// Geometry of a redundant gyro package: N ≥ 3 unit sensing axes h_i in the body frame B.
//
// Measurement model (calibrated rates): y = H ω_B + ε, H = [h_1ᵀ; …; h_Nᵀ] (N×3), cov(ε) = R = diag(σ_i²).
// A gyro subset is a GyroMask: bit (i−1) set ⇔ gyro i used. For a subset S with |S| ≥ 3 and rank 3:
//   * weighted least-squares pseudoinverse  H*_S = (H_Sᵀ R_S⁻¹ H_S)⁻¹ H_Sᵀ R_S⁻¹, returned as a 3×N matrix
//     whose columns for gyros outside S are zero, so ω̂ = H*_S · y for a full-length y;
//   * per-axis noise variance of ω̂: diag((H_Sᵀ R_S⁻¹ H_S)⁻¹), in the units of σ²;
//   * parity matrix V_S ((|S|−3)×N, zero columns outside S): V_S H = 0, V_S V_Sᵀ = I. Its sign is fixed so
//   the
//     first non-zero entry of each row is positive (nominal tetrahedron: p ∝ (1, 1, 1, −√3)).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/result.hpp"

namespace tetra {

using GyroMask = std::uint32_t;
inline constexpr int kMaxGyros = 32;

//! Mask with gyros 1..n set.
inline GyroMask all_gyros(int n) {
  return n >= 32 ? ~GyroMask{0} : ((GyroMask{1} << static_cast<unsigned>(n)) - 1U);
}
//! Mask without gyro `id` (1-based).
inline GyroMask without_gyro(GyroMask mask, int id) {
  return mask & ~(GyroMask{1} << static_cast<unsigned>(id - 1));
}
inline bool has_gyro(GyroMask mask, int id) {
  return ((mask >> static_cast<unsigned>(id - 1)) & 1U) != 0U;
}
int gyro_count(GyroMask mask);  // number of gyros in the mask
//! "1234", "124": the ids in the mask, for files and displays (ids ≥ 10 are comma separated).
std::string mask_to_string(GyroMask mask, int n_gyros);

//! Nominal tetrahedron axes (docs/interfaces.md §1, seed Table 5 nominal rows), 4×3, rows h_iᵀ in B.
Eigen::Matrix<double, 4, 3> nominal_tetrahedron_axes();

class GyroGeometry {
 public:
  //! Axes as rows (N×3, each of unit norm within 1e-6), noise σ_i per gyro (any consistent unit, > 0).
  static Result<GyroGeometry> create(const Eigen::MatrixX3d& axes_B, const Eigen::VectorXd& sigma);
  //! Axes with equal weights (σ_i = 1).
  static Result<GyroGeometry> create(const Eigen::MatrixX3d& axes_B);
  //! The nominal tetrahedron with equal weights.
  static GyroGeometry nominal_tetrahedron();

  int gyro_count() const { return static_cast<int>(axes_B_.rows()); }
  GyroMask all() const { return all_gyros(gyro_count()); }
  const Eigen::MatrixX3d& axes_B() const { return axes_B_; }
  const Eigen::VectorXd& sigma() const { return sigma_; }

  //! True if the subset has at least 3 gyros whose axes span 3-D (condition number below 1e8).
  bool observable(GyroMask mask) const;
  //! 3×N weighted pseudoinverse for the subset (zero columns outside it). Error if not observable.
  Result<Eigen::Matrix3Xd> pseudoinverse(GyroMask mask) const;
  //! diag((H_Sᵀ R_S⁻¹ H_S)⁻¹): variance of each body-axis rate estimate. Error if not observable.
  Result<Eigen::Vector3d> noise_variance_per_axis(GyroMask mask) const;
  //! (|S|−3)×N parity matrix (empty with N columns when |S| = 3). Error if not observable.
  Result<Eigen::MatrixXd> parity_matrix(GyroMask mask) const;
  //! The leave-one-out pseudoinverses: element i (0-based) excludes gyro i+1 from `mask`.
  std::vector<Result<Eigen::Matrix3Xd>> leave_one_out(GyroMask mask) const;

 private:
  GyroGeometry(Eigen::MatrixX3d axes_B, Eigen::VectorXd sigma)
      : axes_B_(std::move(axes_B)), sigma_(std::move(sigma)) {}
  Eigen::MatrixX3d axes_B_;  //!< [-] N×3 unit sensing axes in B
  Eigen::VectorXd sigma_;    //!< [units of y] 1σ noise per gyro (weights R⁻¹ = diag(1/σ²))
};

}  // namespace tetra
