#include "tetra/core/geometry.hpp"

#include <bit>
#include <cmath>
#include <string>

#include <Eigen/Dense>

namespace tetra {

int gyro_count(GyroMask mask) {
  return std::popcount(mask);
}

std::string mask_to_string(GyroMask mask, int n_gyros) {
  std::string out;
  for (int id = 1; id <= n_gyros; ++id) {
    if (!has_gyro(mask, id)) continue;
    if (n_gyros >= 10 && !out.empty()) out += ',';
    out += std::to_string(id);
  }
  return out;
}

Eigen::Matrix<double, 4, 3> nominal_tetrahedron_axes() {
  const double a = 1.0 / std::sqrt(3.0);
  const double b = std::sqrt(2.0) / 2.0;
  const double c = std::sqrt(6.0) / 3.0;
  const double d = std::sqrt(6.0) / 6.0;
  Eigen::Matrix<double, 4, 3> h;
  h << a, 0.0, c,  //
      a, b, -d,    //
      a, -b, -d,   //
      1.0, 0.0, 0.0;
  return h;
}

Result<GyroGeometry> GyroGeometry::create(const Eigen::MatrixX3d& axes_B, const Eigen::VectorXd& sigma) {
  const Eigen::Index n = axes_B.rows();
  if (n < 3) return bad_input("geometry: " + std::to_string(n) + " gyros given, at least 3 are needed");
  if (n > kMaxGyros)
    return bad_input("geometry: at most " + std::to_string(kMaxGyros) + " gyros are supported");
  if (sigma.size() != n) return bad_input("geometry: noise vector size does not match the number of gyros");
  for (Eigen::Index i = 0; i < n; ++i) {
    const double norm = axes_B.row(i).norm();
    if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-6) {
      return bad_input("geometry: axis of gyro " + std::to_string(i + 1) + " has norm " +
                       std::to_string(norm) + ", expected a unit vector");
    }
    if (!std::isfinite(sigma[i]) || sigma[i] <= 0.0) {
      return bad_input("geometry: noise sigma of gyro " + std::to_string(i + 1) + " must be positive");
    }
  }
  GyroGeometry g(axes_B, sigma);
  if (!g.observable(g.all())) return bad_input("geometry: the gyro axes do not span three dimensions");
  return g;
}

Result<GyroGeometry> GyroGeometry::create(const Eigen::MatrixX3d& axes_B) {
  return create(axes_B, Eigen::VectorXd::Ones(axes_B.rows()));
}

GyroGeometry GyroGeometry::nominal_tetrahedron() {
  return GyroGeometry(nominal_tetrahedron_axes(), Eigen::VectorXd::Ones(4));
}

namespace {

// Information matrix HᵀR⁻¹H of the subset.
Eigen::Matrix3d information(const Eigen::MatrixX3d& h, const Eigen::VectorXd& sigma, GyroMask mask) {
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < h.rows(); ++i) {
    if (!has_gyro(mask, static_cast<int>(i + 1))) continue;
    const Eigen::Vector3d hi = h.row(i).transpose();
    info += hi * hi.transpose() / (sigma[i] * sigma[i]);
  }
  return info;
}

}  // namespace

bool GyroGeometry::observable(GyroMask mask) const {
  if (tetra::gyro_count(mask & all()) < 3) return false;
  // Unit-weight information matrix: its conditioning depends on geometry only.
  const Eigen::Matrix3d info = information(axes_B_, Eigen::VectorXd::Ones(gyro_count()), mask & all());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(info);
  const double lo = eig.eigenvalues().minCoeff();
  const double hi = eig.eigenvalues().maxCoeff();
  return lo > 0.0 && hi / lo < 1e8;
}

Result<Eigen::Matrix3Xd> GyroGeometry::pseudoinverse(GyroMask mask) const {
  mask &= all();
  if (!observable(mask)) {
    return bad_input("geometry: gyro subset {" + mask_to_string(mask, gyro_count()) + "} is not observable");
  }
  const Eigen::Matrix3d cov = information(axes_B_, sigma_, mask).inverse();
  Eigen::Matrix3Xd pinv = Eigen::Matrix3Xd::Zero(3, gyro_count());
  for (int i = 0; i < gyro_count(); ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    pinv.col(i) = cov * axes_B_.row(i).transpose() / (sigma_[i] * sigma_[i]);
  }
  return pinv;
}

Result<Eigen::Vector3d> GyroGeometry::noise_variance_per_axis(GyroMask mask) const {
  mask &= all();
  if (!observable(mask)) {
    return bad_input("geometry: gyro subset {" + mask_to_string(mask, gyro_count()) + "} is not observable");
  }
  return Eigen::Vector3d(information(axes_B_, sigma_, mask).inverse().diagonal());
}

Result<Eigen::MatrixXd> GyroGeometry::parity_matrix(GyroMask mask) const {
  mask &= all();
  if (!observable(mask)) {
    return bad_input("geometry: gyro subset {" + mask_to_string(mask, gyro_count()) + "} is not observable");
  }
  const int m = tetra::gyro_count(mask);
  const int n = gyro_count();
  std::vector<int> index;
  Eigen::MatrixXd hs(m, 3);
  for (int i = 0; i < n; ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    hs.row(static_cast<Eigen::Index>(index.size())) = axes_B_.row(i);
    index.push_back(i);
  }
  // Full QR of H_S: the last m−3 columns of Q span the left null space of H_S, orthonormally.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(hs);
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(m, m);
  Eigen::MatrixXd v_sub = q.rightCols(m - 3).transpose();
  for (Eigen::Index r = 0; r < v_sub.rows(); ++r) {
    for (Eigen::Index c = 0; c < v_sub.cols(); ++c) {
      if (std::abs(v_sub(r, c)) > 1e-12) {
        if (v_sub(r, c) < 0) v_sub.row(r) *= -1.0;
        break;
      }
    }
  }
  Eigen::MatrixXd v = Eigen::MatrixXd::Zero(m - 3, n);
  for (int k = 0; k < m; ++k) v.col(index[static_cast<std::size_t>(k)]) = v_sub.col(k);
  return v;
}

std::vector<Result<Eigen::Matrix3Xd>> GyroGeometry::leave_one_out(GyroMask mask) const {
  std::vector<Result<Eigen::Matrix3Xd>> out;
  out.reserve(static_cast<std::size_t>(gyro_count()));
  for (int id = 1; id <= gyro_count(); ++id) out.push_back(pseudoinverse(without_gyro(mask, id)));
  return out;
}

}  // namespace tetra
