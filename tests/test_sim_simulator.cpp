// Simulator: faults change exactly the gyro and span they name; reference; jitter; dropped
// samples; determinism; scenario files.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "sim_test_util.hpp"
#include "test_support.hpp"
#include "tetra/core/units.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::sim {
namespace {

Scenario short_static() {
  Scenario sc = builtin_scenario("static").value();
  sc.duration_s = 60.0;
  sc.rate_hz = 10.0;
  return sc;
}

GyroLog run(const Scenario& sc, const std::vector<std::string>& faults, std::uint64_t seed = 9) {
  SimOptions opt;
  opt.seed = seed;
  for (const auto& f : faults) {
    auto spec = parse_fault_spec(f);
    EXPECT_TRUE(spec.ok()) << f;
    opt.faults.push_back(spec.value());
  }
  auto log = simulate_log(sc, opt);
  EXPECT_TRUE(log.ok()) << (log.ok() ? "" : log.error().message);
  return log.value();
}

bool same(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

struct FaultCase {
  std::string spec;
  int gyro;  // 1-based
  double at;
  double until;  // +inf when none
};

TEST(SimFaults, EveryKindChangesExactlyItsGyroAndSpan) {
  const Scenario sc = short_static();
  const GyroLog clean = run(sc, {});
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<FaultCase> cases = {
      {"gyro=2,kind=bias,at=20,size=0.5,until=40", 2, 20, 40},
      {"gyro=1,kind=ramp,at=10,size=0.01", 1, 10, inf},
      {"gyro=3,kind=scale,at=20,size=0.05,until=30", 3, 20, 30},
      {"gyro=4,kind=stuck,at=20,until=40", 4, 20, 40},
      {"gyro=2,kind=zero,at=30.5,until=31", 2, 30.5, 31},
      {"gyro=1,kind=noise,at=20,size=10,until=40", 1, 20, 40},
      {"gyro=3,kind=spike,at=25.05,size=2", 3, 25.1, 25.2},  // one sample: t = 25.1
      {"gyro=4,kind=dropout,at=20,until=40", 4, 20, 40},
      {"gyro=2,kind=invalid,at=50", 2, 50, inf},
  };
  for (const FaultCase& c : cases) {
    SCOPED_TRACE(c.spec);
    const GyroLog faulty = run(sc, {c.spec});
    ASSERT_EQ(faulty.epochs(), clean.epochs());
    const auto& g = sc.unit.gyros[static_cast<std::size_t>(c.gyro - 1)];
    std::size_t changed = 0;
    for (std::size_t k = 0; k < clean.epochs(); ++k) {
      const double t = clean.time_s[k];
      ASSERT_EQ(faulty.time_s[k], t);
      for (int i = 0; i < 4; ++i) {
        const bool inside = (i == c.gyro - 1) && t >= c.at && t < c.until;
        const double a = clean.value(k, i);
        const double b = faulty.value(k, i);
        if (!inside) {
          // Outside the named gyro and span: bit-identical to the fault-free run.
          ASSERT_TRUE(same(a, b) && clean.is_present(k, i) == faulty.is_present(k, i))
              << "gyro " << i + 1 << " t " << t;
          continue;
        }
        if (!same(a, b) || clean.is_present(k, i) != faulty.is_present(k, i)) ++changed;
        const std::string kind =
            c.spec.substr(c.spec.find("kind=") + 5, c.spec.find(",at") - c.spec.find("kind=") - 5);
        const double s = g.scale_factor_V_per_dps;
        // Tolerances 1e-15 V: one or two roundings of ~0.1 V numbers.
        if (kind == "bias") {
          ASSERT_NEAR(b - a, s * 0.5, 1e-15);
        }
        if (kind == "ramp") {
          ASSERT_NEAR(b - a, s * 0.01 * (t - 10.0), 1e-15);
        }
        if (kind == "scale") {
          ASSERT_NEAR(b - a, 0.05 * (a - g.bias_V), 1e-15);
        }
        if (kind == "stuck") {
          ASSERT_EQ(b, clean.value(199, i));  // the output at t = 19.9 s, the last before `at`
        }
        if (kind == "zero") {
          ASSERT_EQ(b, 0.0);
        }
        if (kind == "spike") {
          ASSERT_NEAR(b - a, s * 2.0, 1e-15);
        }
        if (kind == "dropout") {
          ASSERT_FALSE(faulty.is_present(k, i));
        }
        if (kind == "invalid") {
          ASSERT_TRUE(std::isnan(b) && faulty.is_present(k, i));
        }
      }
    }
    EXPECT_GT(changed, 0u);
  }
}

TEST(SimFaults, NoiseFaultMultipliesTheWhiteNoise) {
  Scenario sc = short_static();
  sc.duration_s = 600.0;
  for (auto& g : sc.unit.gyros) g.noise->bias_instability_dps.reset();  // white noise only
  const GyroLog clean = run(sc, {});
  const GyroLog noisy = run(sc, {"gyro=1,kind=noise,at=0,size=4"});
  std::vector<double> a;
  std::vector<double> b;
  for (std::size_t k = 0; k < clean.epochs(); ++k) {
    a.push_back(clean.value(k, 0));
    b.push_back(noisy.value(k, 0));
  }
  // The same white-noise samples times 4 (the static rate is constant): ratio of stds exactly 4
  // up to rounding (1e-9 relative).
  EXPECT_NEAR(simtest::stddev(b) / simtest::stddev(a), 4.0, 4e-9);
}

TEST(SimFaults, ParseRejectsBadSpecsWithTheField) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"gyro=1,kind=bias,at=5", "size is required"},
      {"gyro=1,kind=stuck,at=5,size=1", "size has no meaning"},
      {"gyro=0,kind=bias,at=5,size=1", "gyro"},
      {"gyro=1,kind=wobble,at=5", "unknown kind"},
      {"gyro=1,kind=bias,at=x,size=1", "at"},
      {"gyro=1,kind=bias,at=5,size=1,until=4", "until must be after"},
      {"gyro=1,kind=spike,at=5,size=1,until=6", "until has no meaning"},
      {"gyro=1,kind=bias,size=1", "at is missing"},
      {"gyro=1,kind=bias,at=5,size=1,colour=red", "unknown field"},
      {"gyro=1,kind=bias,at", "not key=value"},
  };
  for (const auto& [text, needle] : bad) {
    auto r = parse_fault_spec(text);
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.error().message.find(needle), std::string::npos) << text << " -> " << r.error().message;
  }
  auto ok = parse_fault_spec("gyro=3,kind=ramp,at=1.5,size=-0.25,until=9");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(format_fault_spec(*ok), "gyro=3,kind=ramp,at=1.5,size=-0.25,until=9");
}

TEST(SimFaults, NoiseFaultNeedsWhiteNoiseToMultiply) {
  Scenario sc = short_static();
  sc.unit.gyros[2].noise.reset();
  SimOptions opt;
  opt.faults.push_back(parse_fault_spec("gyro=3,kind=noise,at=1,size=3").value());
  auto sim = Simulator::create(sc, opt);
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message.find("gyro 3 has no white noise"), std::string::npos) << sim.error().message;
  opt.faults[0].gyro = 5;
  sim = Simulator::create(sc, opt);
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message.find("gyro 5 does not exist"), std::string::npos) << sim.error().message;
}

TEST(SimSimulator, SameSeedSameOutputDifferentSeedDifferent) {
  Scenario sc = builtin_scenario("orbit").value();
  sc.duration_s = 30.0;
  const GyroLog a = run(sc, {}, 5);
  const GyroLog b = run(sc, {}, 5);
  const GyroLog c = run(sc, {}, 6);
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.reference_wxyz, b.reference_wxyz);
  EXPECT_NE(a.values, c.values);
}

TEST(SimSimulator, ReferenceRateAndNoise) {
  Scenario sc = builtin_scenario("orbit").value();
  sc.duration_s = 2000.0;
  sc.reference.rate_hz = 2.0;
  sc.reference.noise_arcsec = 10.0;
  Truth truth;
  auto log = simulate_log(sc, SimOptions{}, &truth);
  ASSERT_TRUE(log.ok());
  ASSERT_TRUE(log->has_reference);
  std::vector<double> err[3];
  for (std::size_t k = 0; k < log->epochs(); ++k) {
    // 2 Hz reference on a 10 Hz log: every 5th epoch, starting at the first.
    ASSERT_EQ(log->reference_present[k] != 0, k % 5 == 0) << k;
    if (!log->reference_present[k]) continue;
    const Eigen::Vector3d e = quat_log(truth.q_RB[k].conjugate() * from_wxyz(log->reference_wxyz[k]));
    for (int a = 0; a < 3; ++a) err[a].push_back(e[a] / kArcsecToRad);
  }
  // 4000 samples per axis: SE of the std 1/√8000 = 1.1 %; ±5 % is > 4σ. Mean SE 10/√4000 = 0.16".
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(simtest::stddev(err[a]), 10.0, 0.5) << "axis " << a;
    EXPECT_NEAR(simtest::mean(err[a]), 0.0, 0.7) << "axis " << a;
  }
}

TEST(SimSimulator, JitterKeepsTimesIncreasingWithinBounds) {
  Scenario sc = short_static();
  sc.jitter_s = 0.02;
  const GyroLog log = run(sc, {});
  double max_offset = 0.0;
  for (std::size_t k = 0; k < log.epochs(); ++k) {
    const double offset = log.time_s[k] - static_cast<double>(k) / 10.0;
    ASSERT_LE(std::abs(offset), 0.02 + 1e-9);
    max_offset = std::max(max_offset, std::abs(offset));
    if (k > 0) {
      ASSERT_GT(log.time_s[k], log.time_s[k - 1]);
    }
  }
  EXPECT_GT(max_offset, 0.015);  // 600 uniform draws in ±0.02 s: P(all < 0.015) = 0.75⁶⁰⁰ ≈ 0
}

TEST(SimSimulator, DroppedSamplesAtTheRequestedRate) {
  Scenario sc = short_static();
  sc.duration_s = 500.0;
  sc.drop_probability = 0.1;
  const GyroLog log = run(sc, {});
  std::size_t dropped = 0;
  for (auto p : log.present) dropped += p == 0 ? 1 : 0;
  // 20000 Bernoulli(0.1) draws: mean 2000, σ = √(20000·0.1·0.9) = 42; ±200 is > 4σ.
  EXPECT_NEAR(static_cast<double>(dropped), 2000.0, 200.0);
  // The delivered samples are those of the run without drops (drops are their own stream).
  Scenario plain = sc;
  plain.drop_probability = 0.0;
  const GyroLog full = run(plain, {});
  for (std::size_t j = 0; j < log.values.size(); ++j) {
    if (log.present[j]) {
      ASSERT_EQ(log.values[j], full.values[j]);
    }
  }
}

TEST(SimSimulator, StreamingEqualsBatchAndResetRepeats) {
  Scenario sc = builtin_scenario("slews").value();
  sc.duration_s = 20.0;
  auto sim = Simulator::create(sc, SimOptions{});
  ASSERT_TRUE(sim.ok());
  std::vector<double> first;
  SimEpoch e;
  while (sim->next(e)) first.insert(first.end(), e.raw_V.begin(), e.raw_V.end());
  EXPECT_EQ(sim->epochs_done(), 200u);
  sim->reset();
  std::vector<double> second;
  while (sim->next(e)) second.insert(second.end(), e.raw_V.begin(), e.raw_V.end());
  EXPECT_EQ(first, second);
  const GyroLog batch = run(sc, {}, 1);
  EXPECT_EQ(batch.values, first);
}

TEST(SimScenario, YamlFileOverridesTheBuiltIn) {
  const std::string text =
      "scenario: slews\n"
      "duration_s: 100\n"
      "rate_hz: 20\n"
      "acs: {amplitude_deg: 0.1, peak_accel_dps2: 2.0e-5}\n"
      "slews:\n"
      "  - {axis: z, angle_deg: 10, start_s: 10, duration_s: 20}\n"
      "  - {axis: [1, 1, 0], angle_deg: -5, start_s: 50, duration_s: 10}\n"
      "reference: {rate_hz: 5, noise_arcsec: 3}\n"
      "gyro_model: {bias_instability_correlation_s: 50, range_dps: 300}\n"
      "jitter_s: 0.001\n"
      "drop_probability: 0.01\n"
      "faults: [\"gyro=2,kind=bias,at=30,size=0.1\"]\n";
  auto sc = parse_scenario(text, "test.yaml");
  ASSERT_TRUE(sc.ok()) << sc.error().message;
  EXPECT_EQ(sc->motion.kind, MotionKind::kSlews);
  EXPECT_EQ(sc->duration_s, 100.0);
  EXPECT_EQ(sc->rate_hz, 20.0);
  ASSERT_EQ(sc->motion.slews.size(), 2u);
  EXPECT_NEAR(sc->motion.slews[1].axis_B.x(), std::sqrt(0.5), 1e-15);
  EXPECT_EQ(sc->reference.rate_hz, 5.0);
  EXPECT_EQ(sc->model.range_dps, 300.0);
  ASSERT_EQ(sc->faults.size(), 1u);
  EXPECT_EQ(sc->faults[0].gyro, 2);
}

// The warm-up's stage: each gyro's output moves by s_i·c_i·(T(t) − T_cal), T(t) the first-order transient,
// on the same noise samples (the stage draws nothing); a scenario file states it in `thermal:`.
TEST(SimThermal, EachGyroFollowsTheTransientByItsOwnCoefficient) {
  Scenario sc = short_static();
  const GyroLog cold = run(sc, {});
  auto parsed = parse_scenario(
      "scenario: static\nduration_s: 60\nthermal: {start_C: 5, end_C: 25, time_constant_s: 20, "
      "bias_dps_per_K: [1e-4, -2e-4, 0, 3e-4]}\n",
      "warm.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  const GyroLog warm = run(*parsed, {});
  ASSERT_EQ(warm.epochs(), cold.epochs());
  const std::array<double, 4> c = {1e-4, -2e-4, 0.0, 3e-4};
  for (std::size_t k = 0; k < warm.epochs(); ++k) {
    const double t = warm.time_s[k];
    const double kelvin = (5.0 - 25.0) * std::exp(-t / 20.0);  // T(t) − T_cal, T_cal = end_C
    for (int i = 0; i < 4; ++i) {
      const double s = sc.unit.gyros[static_cast<std::size_t>(i)].scale_factor_V_per_dps;
      // 1e-15 V: a few roundings of ~0.1 V numbers (no quantization in this unit's noise).
      ASSERT_NEAR(warm.value(k, i) - cold.value(k, i), s * c[static_cast<std::size_t>(i)] * kelvin, 1e-15)
          << "gyro " << i + 1 << " t " << t;
    }
  }
  // Settled: calibrated_at_C other than the end leaves a constant offset.
  ThermalOptions t;
  t.start_C = 5.0;
  t.end_C = 25.0;
  t.calibrated_at_C = 20.0;
  t.bias_dps_per_K = {1e-4};
  EXPECT_NEAR(t.bias_dps(0, 1e9), 5e-4, 1e-18);
  EXPECT_NEAR(t.bias_dps(0, 0.0), -1.5e-3, 1e-18);
  EXPECT_EQ(t.bias_dps(1, 0.0), 0.0);  // no coefficient: no term
}

TEST(SimScenario, YamlErrorsNameLineAndKey) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"scenario: orbit\nduration: 10\n", "test.yaml:2: unknown key 'duration'"},
      {"scenario: orbit\nrate_hz: fast\n", "test.yaml:2: rate_hz: 'fast' is not a number"},
      {"scenario: sideways\n", "test.yaml:1: scenario: unknown scenario 'sideways'"},
      {"duration_s: 10\n", "missing key 'scenario'"},
      {"scenario: orbit\nfaults: [\"gyro=9,kind=zero,at=1\"]\n", "gyro 9 does not exist"},
      {"scenario: orbit\nacs: {amplitude: 1}\n", "test.yaml:2: acs: unknown key 'amplitude'"},
      {"scenario: orbit\nslews: []\n", "only the 'slews' scenario"},
      {"scenario: static\nrate_hz: -1\n",
       "test.yaml:2: rate_hz must be above 0 and at most 1e+05 Hz, got -1"},
      {"scenario: orbit\norbit_period_s: 6e-299\n",
       "test.yaml:2: orbit_period_s must be from 1200 to 6e+07 s, got 6e-299"},
      {"scenario: orbit\nacs: {amplitude_deg: 1e300}\n",
       "test.yaml:2: acs.amplitude_deg must be from 0 to 45 deg"},
      {"scenario: lab-orbit\npitch_rate_dps: 1e300\n", "test.yaml:2: pitch_rate_dps must be from"},
      {"scenario: static\nduration_s: 1e300\n",
       "test.yaml:2: duration_s must be above 0 and at most 6e+08 s, got 1e+300"},
      {"scenario: orbit\nreference: {noise_arcsec: 1e300}\n", "test.yaml:2: reference.noise_arcsec must be"},
      {"scenario: orbit\nfaults: [\"gyro=1,kind=bias,at=1,size=1e300\"]\n",
       "size: must be finite and at most"},
      {"scenario: [unclosed\n", "test.yaml:"},
      {"scenario: static\nthermal: {start_C: 0, end_C: 20}\n",
       "test.yaml:2: thermal.bias_dps_per_K: missing"},
      {"scenario: static\nthermal: {bias_dps_per_K: [1e-6, 1e-6]}\n",
       "thermal.bias_dps_per_K has 2 coefficients; the unit has 4 gyros"},
      {"scenario: static\nthermal: {start_C: 0, end_C: 20, bias_dps_per_K: [1e-6, 1e-6, 1e-6, 1]}\n",
       "is a bias above 1 deg/s"},
      {"scenario: static\nthermal: {time_constant_s: 0, bias_dps_per_K: [0, 0, 0, 0]}\n",
       "thermal.time_constant_s must be above 0"},
      {"scenario: static\nthermal: {start: 0, bias_dps_per_K: [0, 0, 0, 0]}\n",
       "test.yaml:2: thermal: unknown key 'start'"},
  };
  for (const auto& [text, needle] : bad) {
    auto r = parse_scenario(text, "test.yaml");
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.error().message.find(needle), std::string::npos) << text << " -> " << r.error().message;
  }
}

}  // namespace
}  // namespace tetra::sim

namespace tetra::sim {
namespace {

TEST(SimScenario, ExampleFilesAreValid) {
  for (const char* name : {"examples/sim/orbit_fault.yaml", "examples/sim/slews_custom.yaml",
                           "examples/sim/static_allan.yaml", "examples/sim/warm_up.yaml"}) {
    auto sc = read_scenario(test::source_path(name));
    ASSERT_TRUE(sc.ok()) << name << ": " << sc.error().message;
  }
  // static_allan.yaml loads allan_unit.yaml (seed Table 6): gyro 2 has all of Q, N, B, K.
  auto sc = read_scenario(test::source_path("examples/sim/static_allan.yaml"));
  const GyroNoise& n = *sc->unit.gyros[1].noise;
  EXPECT_EQ(n.quantization_deg, 6e-5);
  EXPECT_EQ(n.rate_random_walk_dps_per_rts, 6e-8);
  EXPECT_FALSE(sc->unit.gyros[0].noise->rate_random_walk_dps_per_rts.has_value());
}

}  // namespace
}  // namespace tetra::sim
