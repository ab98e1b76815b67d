#pragma once
// Shared by the isolation campaigns (test_isolation_adversarial.cpp, test_isolation_cases.cpp): slews,
// scenarios, the configuration per seed, the tallies and the fault cases.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "campaign.hpp"
#include "family_campaign.hpp"  // test::honesty
#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"

namespace tetra::isolation_adversarial {

using K = sim::FaultKind;
using test::run_campaign;

struct SlewCase {
  const char* name;
  Eigen::Vector3d axis_B;
  double angle_deg;
  double duration_s;
};

// From a gentle 5° over 2 min to 30° in 10 s and beyond (peak rate 2Φ/T, peak acceleration
// 2πΦ/T²: 0.08 deg/s and 2.2e-3 deg/s² ... 10 deg/s and 16 deg/s²).
inline const std::vector<SlewCase>& slews() {
  static const std::vector<SlewCase> all = {
      {"5deg/120s x", Eigen::Vector3d::UnitX(), 5.0, 120.0},
      {"30deg/60s y", Eigen::Vector3d::UnitY(), 30.0, 60.0},
      {"30deg/10s z", Eigen::Vector3d::UnitZ(), 30.0, 10.0},
      {"-45deg/15s diag", Eigen::Vector3d(1.0, -1.0, 1.0).normalized(), -45.0, 15.0},
      {"10deg/2s x+z", Eigen::Vector3d(1.0, 0.0, 1.0).normalized(), 10.0, 2.0},
  };
  return all;
}

constexpr double kSlewStart_s = 30.0;  //!< [s] the detectors have a full history by then

inline sim::Scenario slew_scenario(int n_gyros, const SlewCase& slew, bool reference, double after_s = 40.0) {
  auto sc = sim::builtin_scenario("slews");
  EXPECT_TRUE(sc.ok());
  sc->unit = test::unit_with(n_gyros);
  sc->motion.acs.amplitude_deg = 0.04;
  sc->motion.acs.peak_accel_dps2 = 1e-4;
  sc->motion.slews = {{slew.axis_B, slew.angle_deg, kSlewStart_s, slew.duration_s}};
  sc->duration_s = kSlewStart_s + slew.duration_s + after_s;
  sc->reference.rate_hz = reference ? 1.0 : 0.0;
  sc->reference.noise_arcsec = 5.0;
  return *sc;
}

// The two acceleration bounds of docs/fdi.md: the orbit's (2e-4 deg/s², which every slew here exceeds: a
// bound too low must not make a wrong exclusion) and the default (1e-3).
inline fdi::PipelineConfig config_for(std::uint64_t seed) {
  fdi::PipelineConfig c;
  c.max_angular_acceleration_dps2 = seed % 2 == 0 ? 2e-4 : 1e-3;
  return c;
}

using test::fault;

//! The built-in orbit with N gyros, gentle attitude control (0.04°, 1e-4 deg/s²) and, at `reference_hz`, the
//! 5″ reference.
inline Result<sim::Scenario> quiet_orbit(int n, double duration_s, double reference_hz) {
  auto sc = sim::builtin_scenario("orbit");
  if (!sc) return sc;
  sc->unit = test::unit_with(n);
  sc->motion.acs.amplitude_deg = 0.04;
  sc->motion.acs.peak_accel_dps2 = 1e-4;
  sc->duration_s = duration_s;
  sc->reference.rate_hz = reference_hz;
  sc->reference.noise_arcsec = 5.0;
  return sc;
}

//! Exclusions of a gyro with no fault begun by then (the promise's violations), as text.
inline std::string wrong_exclusions(const test::CampaignRun& run, const std::vector<sim::FaultSpec>& faults) {
  std::string out;
  for (const auto& e : run.events) {
    if (e.type != fdi::EventType::kIsolated) continue;
    const double t = ns_to_seconds(e.stamp_ns);
    const bool faulty = std::any_of(faults.begin(), faults.end(),
                                    [&](const sim::FaultSpec& f) { return f.gyro == e.gyro && f.at_s <= t; });
    if (!faulty) out += fdi::to_json(e, 6) + "\n";
  }
  return out;
}

struct Tally {
  int runs = 0;
  int isolated = 0;  //!< the faulty gyro excluded
  int unisolated = 0;
  int wrong = 0;  //!< a healthy gyro excluded
  std::vector<double> delays_s;
};

inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

//! One run into its fault's tally: a wrong exclusion (described into `what`), the faulty gyro isolated (with
//! its delay from `at_s`), or `unisolated`.
inline void tally(Tally& t, const test::CampaignRun& run, const std::vector<sim::FaultSpec>& faults,
                  double at_s, const std::string& label, int n, std::string& what) {
  ++t.runs;
  if (!wrong_exclusions(run, faults).empty()) {
    ++t.wrong;
    what += label + ":\n" + test::describe(run, n);
  } else if (run.isolated_gyro) {
    ++t.isolated;
    t.delays_s.push_back(*run.first_isolated_s - at_s);
  } else if (run.unisolated) {
    ++t.unisolated;
  }
}

inline void print_table(const std::map<std::string, Tally>& table) {
  std::printf("%-14s %6s %9s %11s %6s %12s %9s\n", "fault", "runs", "isolated", "unisolated", "wrong",
              "median delay", "max delay");
  for (const auto& [kind, t] : table) {
    const double max = t.delays_s.empty() ? 0.0 : *std::max_element(t.delays_s.begin(), t.delays_s.end());
    std::printf("%-14s %6d %8.0f%% %11d %6d %10.1f s %7.1f s\n", kind.c_str(), t.runs,
                t.runs ? 100.0 * t.isolated / t.runs : 0.0, t.unisolated, t.wrong, median(t.delays_s), max);
  }
}

inline std::uint64_t filter_bias_seeds(std::uint64_t fallback) {
  const char* v = std::getenv("TETRA_FILTER_BIAS_SEEDS");
  const long n = v != nullptr ? std::strtol(v, nullptr, 10) : 0;
  return n > 0 ? static_cast<std::uint64_t>(n) : fallback;
}

struct FaultCase {
  const char* name;
  K kind;
  double size;
};

inline const std::vector<FaultCase>& fault_cases() {
  static const std::vector<FaultCase> all = {
      {"bias 1e-3", K::kBias, 1e-3},   {"bias -3e-3", K::kBias, -3e-3}, {"bias 2e-2", K::kBias, 2e-2},
      {"ramp 1e-5", K::kRamp, 1e-5},   {"ramp 1e-3", K::kRamp, 1e-3},   {"scale +5%", K::kScale, 0.05},
      {"scale -50%", K::kScale, -0.5}, {"stuck", K::kStuck, 0.0},       {"zero", K::kZero, 0.0},
      {"noise x10", K::kNoise, 10.0},  {"spike 0.05", K::kSpike, 0.05}, {"dropout", K::kDropout, 0.0},
      {"invalid", K::kInvalid, 0.0},
  };
  return all;
}

}  // namespace tetra::isolation_adversarial
