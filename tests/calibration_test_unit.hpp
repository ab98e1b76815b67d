#pragma once
// The unit of the calibration tests: the seed's as-built unit (Tables 4–5) with white rate noise only,
// N = 3e-5 deg/√s (no bias instability), and no 1σ of its own.
#include "tetra/core/calibration_file.hpp"

namespace tetra::test {

inline Calibration white_noise_unit() {
  Calibration unit = seed_as_built_unit();
  for (auto& g : unit.gyros) {
    GyroNoise noise;
    noise.arw_dps_rtHz = 3e-5;
    g.noise = noise;
    g.sigma.reset();
  }
  return unit;
}

}  // namespace tetra::test
