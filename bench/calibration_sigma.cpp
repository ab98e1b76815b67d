// Seeded study: are the calibration's 1σ honest? Simulates the seed turntable plan (6 deg/s, one
// revolution per sequence, 10 Hz, latitude −23.2°) for many seeds with several noise models, calibrates
// in process with both methods, with and without the unit's noise model, and prints the RMS of
// error/σ for s, β and the axis components and the fraction with |error/σ| > 3.
// Usage: calibration_sigma [RUNS=330]   (330 runs × 4 gyros = 1 320 calibrations per case)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tetra/core/calibration.hpp"
#include "tetra/sim/turntable.hpp"

namespace {

using tetra::Calibration;
using tetra::CalibrationMethod;
using tetra::GyroNoise;

struct Case {
  std::string name;
  GyroNoise noise;
  double correlation_s = 100.0;
};

struct Tally {
  double sum_z2[3] = {0, 0, 0};  // s, β, axis
  int over3[3] = {0, 0, 0};
  int count[3] = {0, 0, 0};
  void add(int k, double z) {
    sum_z2[k] += z * z;
    over3[k] += std::abs(z) > 3.0 ? 1 : 0;
    ++count[k];
  }
};

Calibration unit_with(const GyroNoise& noise) {
  Calibration unit = tetra::seed_as_built_unit();
  for (auto& g : unit.gyros) {
    g.noise = noise;
    g.sigma.reset();
  }
  return unit;
}

void tally_run(const Calibration& truth, const Calibration& estimate, Tally& tally) {
  for (std::size_t i = 0; i < truth.gyros.size(); ++i) {
    const auto& t = truth.gyros[i];
    const auto& e = estimate.gyros[i];
    tally.add(0, (e.scale_factor_V_per_dps - t.scale_factor_V_per_dps) / e.sigma->scale_factor_V_per_dps);
    tally.add(1, (e.bias_V - t.bias_V) / e.sigma->bias_V);
    for (int k = 0; k < 3; ++k) tally.add(2, (e.axis_B(k) - t.axis_B(k)) / e.sigma->axis(k));
  }
}

void print(const std::string& what, const Tally& t) {
  std::printf("%-44s", what.c_str());
  for (int k = 0; k < 3; ++k) {
    std::printf("  %6.2f %5.1f%%", std::sqrt(t.sum_z2[k] / t.count[k]), 100.0 * t.over3[k] / t.count[k]);
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 330;
  std::vector<Case> cases;
  GyroNoise white;
  white.arw_dps_rtHz = 3e-5;
  cases.push_back({"white N=3e-5", white});
  GyroNoise seed = *tetra::seed_as_built_unit().gyros[0].noise;
  cases.push_back({"seed unit N=3e-5 B=5e-6 Tc=100s", seed});
  cases.push_back({"seed unit, Tc=20s", seed, 20.0});
  GyroNoise walk = white;
  walk.rate_random_walk_dps_per_rts = 3e-7;
  cases.push_back({"N=3e-5 K=3e-7", walk});
  std::printf("%d runs x 4 gyros per case; columns: RMS(z) and %% |z|>3 for s, beta, axis\n", runs);
  for (const Case& c : cases) {
    const Calibration unit = unit_with(c.noise);
    tetra::sim::GyroModelOptions model;
    model.bias_instability_correlation_s = c.correlation_s;
    for (const auto method : {CalibrationMethod::kSixteen, CalibrationMethod::kBatch}) {
      Tally plain;
      Tally modelled;
      for (int run = 0; run < runs; ++run) {
        const tetra::sim::TurntablePlan plan;
        auto log = tetra::sim::simulate_turntable(unit, plan, 1000 + static_cast<std::uint64_t>(run), model);
        auto motion = tetra::analyze_turntable(*log, plan.latitude_deg);
        if (!log || !motion) return 1;
        tetra::CalibrationOptions options;
        options.method = method;
        auto a = tetra::calibrate(*log, *motion, options);
        options.noise.assign(unit.gyros.size(), c.noise);
        options.bias_instability_correlation_s = c.correlation_s;
        auto b = tetra::calibrate(*log, *motion, options);
        if (!a || !b) return 1;
        tally_run(unit, a->calibration, plain);
        tally_run(unit, b->calibration, modelled);
      }
      const std::string m = method == CalibrationMethod::kBatch ? " batch" : " sixteen";
      print(c.name + m + ", white 1σ", plain);
      print(c.name + m + ", noise model", modelled);
    }
  }
  return 0;
}
