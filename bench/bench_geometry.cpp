// Geometry costs: pseudoinverse and parity matrix of a subset (done once per subset and cached by
// the pipeline) and applying a cached pseudoinverse (done every epoch).
#include <benchmark/benchmark.h>

#include "tetra/core/geometry.hpp"

namespace {

void BM_Pseudoinverse(benchmark::State& state) {
  const auto g = tetra::GyroGeometry::nominal_tetrahedron();
  for (auto _ : state) benchmark::DoNotOptimize(g.pseudoinverse(g.all()));
}
BENCHMARK(BM_Pseudoinverse);

void BM_ParityMatrix(benchmark::State& state) {
  const auto g = tetra::GyroGeometry::nominal_tetrahedron();
  for (auto _ : state) benchmark::DoNotOptimize(g.parity_matrix(g.all()));
}
BENCHMARK(BM_ParityMatrix);

void BM_ApplyCachedPseudoinverse(benchmark::State& state) {
  const auto g = tetra::GyroGeometry::nominal_tetrahedron();
  const Eigen::Matrix3Xd pinv = *g.pseudoinverse(g.all());
  Eigen::VectorXd y = Eigen::VectorXd::Random(4);
  for (auto _ : state) {
    Eigen::Vector3d w = pinv * y;
    benchmark::DoNotOptimize(w);
  }
}
BENCHMARK(BM_ApplyCachedPseudoinverse);

}  // namespace

BENCHMARK_MAIN();
