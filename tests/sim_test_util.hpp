#pragma once
// Small helpers for the simulator's tests: sample statistics and an overlapping Allan deviation
// (written here on purpose, independent of the library under test).

#include <cmath>
#include <cstddef>
#include <vector>

#include "tetra/core/calibration_file.hpp"

namespace tetra::simtest {

inline double mean(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v;
  return s / static_cast<double>(x.size());
}

inline double stddev(const std::vector<double>& x) {
  const double m = mean(x);
  double s = 0.0;
  for (double v : x) s += (v - m) * (v - m);
  return std::sqrt(s / static_cast<double>(x.size() - 1));
}

//! Overlapping Allan deviation of rate samples `y` (interval dt) at τ = m·dt.
inline double overlapping_adev(const std::vector<double>& y, std::size_t m) {
  std::vector<double> theta(y.size() + 1, 0.0);  // integrated angle × (1/dt)
  for (std::size_t i = 0; i < y.size(); ++i) theta[i + 1] = theta[i] + y[i];
  const std::size_t n = theta.size();
  double sum = 0.0;
  std::size_t terms = 0;
  for (std::size_t k = 0; k + 2 * m < n; ++k) {
    const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
    sum += d * d;
    ++terms;
  }
  const double md = static_cast<double>(m);
  return std::sqrt(sum / (2.0 * md * md * static_cast<double>(terms)));
}

//! A unit with the seed's scale factors, biases and axes and the given noise (or none).
inline Calibration unit_with_noise(const std::optional<GyroNoise>& noise) {
  Calibration unit = seed_as_built_unit();
  for (auto& g : unit.gyros) g.noise = noise;
  return unit;
}

}  // namespace tetra::simtest
