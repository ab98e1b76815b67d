// Gyro-model stages, each alone: seeded statistics with stated tolerances.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim_test_util.hpp"
#include "tetra/sim/gyro_model.hpp"
#include "tetra/sim/random.hpp"

namespace tetra::sim {
namespace {

using simtest::mean;
using simtest::overlapping_adev;
using simtest::stddev;

GyroCalibration gyro_with(const GyroNoise& noise) {
  GyroCalibration g = seed_as_built_unit().gyros[1];  // s = 0.0785 V/(deg/s), β = 0.0004 V
  g.noise = noise;
  return g;
}

TEST(SimRandom, NormalSamplerHasUnitMomentsAndIsReproducible) {
  Rng a(42);
  Rng b(42);
  std::vector<double> x(400000);
  for (double& v : x) {
    v = a.normal();
    ASSERT_EQ(v, b.normal());  // same seed, same stream, bit for bit
  }
  // n = 4e5: standard error of the mean 1/√n = 1.6e-3, of the std 1/√(2n) = 1.1e-3; 4σ bounds.
  EXPECT_NEAR(mean(x), 0.0, 0.0064);
  EXPECT_NEAR(stddev(x), 1.0, 0.0045);
  // Kurtosis of a normal is 3 (SE √(24/n) = 7.7e-3): catches a uniform or otherwise wrong shape.
  double m4 = 0.0;
  for (double v : x) m4 += v * v * v * v;
  EXPECT_NEAR(m4 / static_cast<double>(x.size()), 3.0, 0.04);
}

TEST(SimRandom, StreamsDifferPerStageAndGyro) {
  EXPECT_NE(stream_seed(1, Stream::kWhiteNoise, 0), stream_seed(1, Stream::kWhiteNoise, 1));
  EXPECT_NE(stream_seed(1, Stream::kWhiteNoise, 0), stream_seed(1, Stream::kBiasInstability, 0));
  EXPECT_NE(stream_seed(1, Stream::kWhiteNoise, 0), stream_seed(2, Stream::kWhiteNoise, 0));
}

TEST(SimGyroModel, ScaleFactorAndBiasAreExactWithoutNoise) {
  GyroCalibration g = seed_as_built_unit().gyros[0];
  g.noise.reset();
  GyroChannel ch(g, GyroModelOptions{}, 0.1, 7, 0);
  const Eigen::Vector3d omega_dps(1.5, -2.0, 0.25);
  // The model is g = s·(h·ω) + β with nothing else: equality to rounding (1e-15 V).
  EXPECT_NEAR(ch.sample_V(omega_dps, 3.0), g.scale_factor_V_per_dps * g.axis_B.dot(omega_dps) + g.bias_V,
              1e-15);
}

TEST(SimGyroModel, WhiteNoiseStandardDeviationAndAllanSlope) {
  GyroNoise noise;
  noise.arw_dps_rtHz = 3.0e-5;  // N [deg/√s]
  const double dt = 0.01;
  GyroChannel ch(gyro_with(noise), GyroModelOptions{}, dt, 11, 0);
  std::vector<double> y(200000);  // 2000 s at 100 Hz
  for (double& v : y) v = ch.white_noise_dps();
  // σ = N/√Δt = 3e-4 deg/s; SE of a std from 2e5 samples is 1/√(2n) = 0.16 %: 1 % is 6σ.
  EXPECT_NEAR(stddev(y) / (3.0e-5 / std::sqrt(dt)), 1.0, 0.01);
  // Allan deviation of white rate noise: N/√τ. At τ = 0.1 s and 1 s the overlapping estimate has
  // a relative SE below 1/√(2·(2000/1)) ≈ 1.6 %; 5 % is > 3σ.
  const double adev_01 = overlapping_adev(y, 10);
  const double adev_1 = overlapping_adev(y, 100);
  EXPECT_NEAR(adev_01 / (3.0e-5 / std::sqrt(0.1)), 1.0, 0.05);
  EXPECT_NEAR(adev_1 / 3.0e-5, 1.0, 0.05);
  // log-log slope −1/2 over one decade; its error is at most the sum of the two relative errors
  // (≈ 2 %/ln 10 ≈ 0.01 at 1σ): ±0.04.
  EXPECT_NEAR(std::log10(adev_1 / adev_01), -0.5, 0.04);
}

TEST(SimGyroModel, BiasInstabilityIsGaussMarkovWithStatedVarianceAndCorrelation) {
  GyroNoise noise;
  noise.bias_instability_dps = 5.0e-6;  // B
  const double dt = 0.01;
  GyroModelOptions opt;
  opt.bias_instability_correlation_s = 1.0;
  GyroChannel ch(gyro_with(noise), opt, dt, 5, 0);
  std::vector<double> b(1000000);  // 10⁴ s = 10⁴ correlation times
  for (double& v : b) v = ch.bias_instability_dps();
  const double sigma = kGaussMarkovSigmaPerB * 5.0e-6;
  EXPECT_DOUBLE_EQ(ch.gauss_markov_sigma_dps(), sigma);
  // Process variance σ_GM²: ~T/(2T_c) = 5000 independent samples, SE of a variance √(2/5000) = 2 %;
  // 8 % is 4σ.
  const double sd = stddev(b);
  EXPECT_NEAR(sd * sd / (sigma * sigma), 1.0, 0.08);
  // Autocorrelation at lag T_c is e⁻¹ = 0.368 (SE ≈ 1/√5000 · O(1) ≈ 0.014): ±0.05.
  const std::size_t lag = 100;
  double c0 = 0.0;
  double c1 = 0.0;
  const double m = mean(b);
  for (std::size_t i = 0; i + lag < b.size(); ++i) {
    c0 += (b[i] - m) * (b[i] - m);
    c1 += (b[i] - m) * (b[i + lag] - m);
  }
  EXPECT_NEAR(c1 / c0, std::exp(-1.0), 0.05);
  // Allan deviation peaks at 0.664·B near τ = 1.893·T_c (the calibration of σ_GM/B); the estimate
  // at τ = 1.9 s from 10⁴ s has a relative SE of ~2 %: ±7 %.
  EXPECT_NEAR(overlapping_adev(b, 190) / (0.6643 * 5.0e-6), 1.0, 0.07);
}

TEST(SimGyroModel, RateRandomWalkVarianceGrowsLinearly) {
  GyroNoise noise;
  noise.rate_random_walk_dps_per_rts = 7.0e-8;  // K
  const double dt = 0.1;
  const int runs = 2000;
  const int steps = 1000;  // 100 s
  std::vector<double> end(runs);
  for (int r = 0; r < runs; ++r) {
    GyroChannel ch(gyro_with(noise), GyroModelOptions{}, dt, static_cast<std::uint64_t>(r) + 100, 0);
    double w = 0.0;
    for (int k = 0; k < steps; ++k) w = ch.rate_random_walk_dps(0.0);
    end[static_cast<std::size_t>(r)] = w;
  }
  // Var = K²·t at t = 100 s; 2000 independent runs: SE of a variance √(2/2000) = 3.2 %; ±13 % is 4σ.
  const double sd = stddev(end);
  EXPECT_NEAR(sd * sd / (7.0e-8 * 7.0e-8 * 100.0), 1.0, 0.13);
}

TEST(SimGyroModel, RateRampIsDeterministic) {
  GyroNoise noise;
  noise.rate_ramp_dps_per_s = 2.0e-6;  // R
  GyroChannel ch(gyro_with(noise), GyroModelOptions{}, 0.1, 1, 0);
  EXPECT_DOUBLE_EQ(ch.rate_random_walk_dps(50.0), 1.0e-4);
}

TEST(SimGyroModel, QuantizationStepAndNoDriftOfTheIntegral) {
  GyroNoise noise;
  noise.quantization_deg = 6.0e-5;  // Q
  const double dt = 0.01;
  const GyroCalibration g = gyro_with(noise);
  GyroChannel ch(g, GyroModelOptions{}, dt, 3, 0);
  const double step_V = std::abs(g.scale_factor_V_per_dps) * std::sqrt(12.0) * 6.0e-5 / dt;
  EXPECT_NEAR(ch.quantization_step_V(), step_V, 1e-15);
  double in_integral = 0.0;
  double out_integral = 0.0;
  std::vector<double> out(100000);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double v = 0.1234567 + 0.01 * std::sin(0.001 * static_cast<double>(k));  // [V] not on the grid
    out[k] = ch.quantize_V(v);
    in_integral += v * dt;
    out_integral += out[k] * dt;
    // Every output is an integer multiple of the step (to rounding, 1e-9 of a step).
    const double count = out[k] / step_V;
    ASSERT_NEAR(count, std::round(count), 1e-9) << "sample " << k;
    // The integrated output stays within half a step (plus rounding) of the integrated input.
    ASSERT_LE(std::abs(out_integral - in_integral), 0.5 * step_V * dt * (1.0 + 1e-6)) << "sample " << k;
  }
  // Allan deviation of angle quantization: √3·Q/τ, exact when the quantization errors of successive
  // samples are independent and uniform. The input here sweeps slowly through the grid, so the
  // errors are close to that at lag 1: at τ = Δt we require ±10 % (a wrong step, e.g. δ = Q
  // instead of √12·Q, is off by 3.5×). At longer τ the slow sinusoid of the input dominates.
  const double expected_V = std::sqrt(3.0) * 6.0e-5 / dt * std::abs(g.scale_factor_V_per_dps);
  EXPECT_NEAR(overlapping_adev(out, 1) / expected_V, 1.0, 0.1);
}

TEST(SimGyroModel, SaturationClampsToTheMeasuringRange) {
  GyroCalibration g = seed_as_built_unit().gyros[0];
  g.noise.reset();
  GyroModelOptions opt;
  opt.range_dps = 10.0;
  GyroChannel ch(g, opt, 0.1, 1, 0);
  const double high = g.scale_factor_V_per_dps * 10.0 + g.bias_V;
  EXPECT_DOUBLE_EQ(ch.sample_axis_V(25.0, 0.0), high);
  EXPECT_DOUBLE_EQ(ch.sample_axis_V(-25.0, 0.0), -g.scale_factor_V_per_dps * 10.0 + g.bias_V);
  EXPECT_DOUBLE_EQ(ch.sample_axis_V(5.0, 0.0), g.scale_factor_V_per_dps * 5.0 + g.bias_V);
}

}  // namespace
}  // namespace tetra::sim
