// Built with `pkg-config --cflags --libs tetra` only: the pkg-config file is enough to compile and link.
#include <cstdio>

#include "tetra/core/geometry.hpp"

int main() {
  const auto axes = tetra::nominal_tetrahedron_axes();
  std::printf("tetra via pkg-config: %d gyro axes\n", static_cast<int>(axes.rows()));
  return axes.rows() == 4 ? 0 : 1;
}
