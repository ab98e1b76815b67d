// Geometry of the nominal tetrahedron and of general N-gyro packages (docs/interfaces.md §1).
#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "tetra/core/geometry.hpp"

namespace tetra {
namespace {

constexpr double kTight = 1e-12;  // exact algebra in double precision: a few ulps of O(1) numbers

TEST(Geometry, NominalAxesAreUnitAndGramIsDiag211) {
  const auto h = nominal_tetrahedron_axes();
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(h.row(i).norm(), 1.0, kTight);
  const Eigen::Matrix3d gram = h.transpose() * h;
  EXPECT_TRUE(gram.isApprox(Eigen::Vector3d(2, 1, 1).asDiagonal().toDenseMatrix(), kTight)) << gram;
  // h1, h2, h3 mutually orthogonal.
  EXPECT_NEAR(h.row(0).dot(h.row(1)), 0.0, kTight);
  EXPECT_NEAR(h.row(0).dot(h.row(2)), 0.0, kTight);
  EXPECT_NEAR(h.row(1).dot(h.row(2)), 0.0, kTight);
}

TEST(Geometry, PseudoinverseIsLeftInverse) {
  const auto g = GyroGeometry::nominal_tetrahedron();
  const auto pinv = g.pseudoinverse(g.all());
  ASSERT_TRUE(pinv.ok());
  const Eigen::Matrix3d eye = *pinv * g.axes_B();
  EXPECT_TRUE(eye.isApprox(Eigen::Matrix3d::Identity(), kTight)) << eye;
}

TEST(Geometry, ParityAnnihilatesHAndIsOrthonormal) {
  const auto g = GyroGeometry::nominal_tetrahedron();
  const auto v = g.parity_matrix(g.all());
  ASSERT_TRUE(v.ok());
  ASSERT_EQ(v->rows(), 1);
  ASSERT_EQ(v->cols(), 4);
  EXPECT_LT((*v * g.axes_B()).norm(), kTight);
  EXPECT_NEAR((*v * v->transpose())(0, 0), 1.0, kTight);
  // Parity vector ∝ (1, 1, 1, −√3), normalized: divide by √6.
  const Eigen::RowVector4d expected = Eigen::RowVector4d(1, 1, 1, -std::sqrt(3.0)) / std::sqrt(6.0);
  EXPECT_TRUE(v->isApprox(expected, kTight)) << *v;
}

TEST(Geometry, NoiseAmplificationAllAndLeaveOneOut) {
  const auto g = GyroGeometry::nominal_tetrahedron();
  const auto all = g.noise_variance_per_axis(g.all());
  ASSERT_TRUE(all.ok());
  EXPECT_TRUE(all->isApprox(Eigen::Vector3d(0.5, 1, 1), kTight)) << all->transpose();
  const Eigen::Vector3d expected[4] = {{1, 1, 5}, {1, 4, 2}, {1, 4, 2}, {1, 1, 1}};
  for (int id = 1; id <= 4; ++id) {
    const auto var = g.noise_variance_per_axis(without_gyro(g.all(), id));
    ASSERT_TRUE(var.ok()) << id;
    EXPECT_TRUE(var->isApprox(expected[id - 1], kTight))
        << "gyro " << id << " excluded: " << var->transpose();
  }
}

TEST(Geometry, LeaveOneOutSolutionsInvertTheirSubset) {
  const auto g = GyroGeometry::nominal_tetrahedron();
  const auto loo = g.leave_one_out(g.all());
  ASSERT_EQ(loo.size(), 4U);
  const Eigen::Vector3d omega(0.3, -1.2, 0.7);
  const Eigen::Vector4d y = g.axes_B() * omega;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(loo[static_cast<std::size_t>(i)].ok());
    const auto& p = *loo[static_cast<std::size_t>(i)];
    EXPECT_NEAR(p.col(i).norm(), 0.0, 0.0) << "excluded gyro must have a zero column";
    Eigen::Vector4d corrupted = y;
    corrupted[i] += 100.0;  // a huge fault on the excluded gyro must not matter
    EXPECT_TRUE((p * corrupted).isApprox(omega, kTight));
  }
  // With three gyros there is no parity left.
  const auto v3 = g.parity_matrix(without_gyro(g.all(), 2));
  ASSERT_TRUE(v3.ok());
  EXPECT_EQ(v3->rows(), 0);
}

TEST(Geometry, WeightedPseudoinverseFavorsQuietGyros) {
  // Six gyros: two triads. The noisy triad should get less weight; estimate variance matches theory.
  Eigen::MatrixX3d axes(6, 3);
  axes << Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity();
  Eigen::VectorXd sigma(6);
  sigma << 1, 1, 1, 2, 2, 2;
  const auto g = GyroGeometry::create(axes, sigma);
  ASSERT_TRUE(g.ok());
  const auto pinv = g->pseudoinverse(g->all());
  ASSERT_TRUE(pinv.ok());
  EXPECT_NEAR((*pinv)(0, 0), 0.8, kTight);  // weights 1 : 1/4 → 0.8 : 0.2
  EXPECT_NEAR((*pinv)(0, 3), 0.2, kTight);
  const auto var = g->noise_variance_per_axis(g->all());
  ASSERT_TRUE(var.ok());
  EXPECT_NEAR((*var)[0], 0.8, kTight);  // 1/(1 + 1/4)
  const auto v = g->parity_matrix(g->all());
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v->rows(), 3);
  EXPECT_LT((*v * axes).norm(), kTight);
  EXPECT_TRUE((*v * v->transpose()).isApprox(Eigen::Matrix3d::Identity(), kTight));
}

TEST(Geometry, RejectsBadInput) {
  Eigen::MatrixX3d two(2, 3);
  two << 1, 0, 0, 0, 1, 0;
  EXPECT_FALSE(GyroGeometry::create(two).ok());
  Eigen::MatrixX3d coplanar(4, 3);
  coplanar << 1, 0, 0, 0, 1, 0, std::sqrt(0.5), std::sqrt(0.5), 0, -1, 0, 0;
  const auto r = GyroGeometry::create(coplanar);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("span"), std::string::npos);
  Eigen::MatrixX3d nonunit = nominal_tetrahedron_axes();
  nonunit(0, 0) = 0.9;
  EXPECT_FALSE(GyroGeometry::create(nonunit).ok());
  const auto g = GyroGeometry::nominal_tetrahedron();
  EXPECT_FALSE(g.pseudoinverse(0b0011).ok());
  EXPECT_FALSE(g.observable(0b0011));
}

TEST(Geometry, MaskHelpers) {
  EXPECT_EQ(all_gyros(4), 0b1111U);
  EXPECT_EQ(without_gyro(0b1111U, 2), 0b1101U);
  EXPECT_EQ(mask_to_string(0b1101U, 4), "134");
  EXPECT_EQ(gyro_count(0b1101U), 3);
}

}  // namespace
}  // namespace tetra
