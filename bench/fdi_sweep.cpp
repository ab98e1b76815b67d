// Long fault-free sweep and detection delays of the fusion pipeline (bench/fdi_sweep.sh, docs/fdi.md
// "Detection"): the simulator's default unit (bias instability B = 5e-6 deg/s) with N = 4, 5, 6 gyros,
// straight into the pipeline in process, one-hour orbits on every thread.
//
//   fdi_sweep [--hours H] [--jobs J] [--delay-seeds S] [--arl0 EPOCHS] [--unit CAL.yaml] [--quantization DEG]
//             [--rate-random-walk K] [--rate-ramp R] [--run-hours L] [--reference 1] [--three-gyro-hours H]
//
// --unit replaces the default unit by a calibration file's (its own N only; e.g. the coarsely quantized
// examples/sim/allan_unit.yaml): the simulator runs that unit and the pipeline reads the same file.
// --quantization gives every gyro of the default unit an angle quantization Q [deg] (N = 4, 5, 6 quantized).
// --rate-random-walk K [deg/s/√s] and --rate-ramp R [deg/s²] state (in `noise:`) and simulate on every gyro
// of the default unit a rate random walk and a rate ramp (+R on each gyro). --run-hours L runs H/L orbits of
// L hours each instead of H one-hour ones, so a random walk or a ramp grows for L hours unreset.
//
// --arl0 lowers the CUSUM's design in-control ARL so that a sweep of a few hundred hours counts enough false
// alarms to test the threshold computation itself (at the default 1e8, 1,000 h expect 0.4). It sets the
// budget's unit false_alarm_probability to 1/(10 ARL0) (the CUSUM's share is 10): every test scales with it.
//
// --three-gyro-hours runs H fault-free hours of the unit's first three gyros (no parity: the own noise level
// and, with --reference 1, the reference's innovations are the detectors; docs/fdi.md "Three gyros") and
// counts their `detected` events: each names a healthy gyro.
//
// Prints per N: false alarms (`detected` events) per 1,000 h against the design rate (1/ARL₀ of the CUSUM
// plus the χ² per-epoch probability), and a table of detection delays of the documented faults against the
// CUSUM theory of fdi/include/tetra/fdi/detectors.hpp.

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "../tests/fusion/units.hpp"
#include "gyro_series.hpp"
#include "subset_cache.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"
#include "tetra/fdi/detectors.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/sim/simulator.hpp"

namespace {

using namespace tetra;
using test::unit_with;

constexpr double kRateHz = 10.0;

struct RunOutcome {
  int detections = 0;
  int own_level = 0;             //!< detections by a gyro's own noise level (three gyros)
  int reference_rejections = 0;  //!< reference_rejected events (--reference 1)
  std::array<int, 7> by_test{};  //!< detections per DetectionTest
  double first_detected_s = -1.0;
  int noise_model = 0;                     //!< noise_model events (the data showed the noise optimistic)
  std::vector<std::string> detected_json;  //!< --events 1: each detected event, with its ledger rows
};

//! One simulated run of `duration_s` straight into a pipeline; counts `detected` events.
double g_false_alarm_probability = fdi::PipelineConfig{}.false_alarm_probability;  // set once by main
std::optional<Calibration> g_unit;                                                 // --unit; set once by main
double g_quantization_deg = 0.0;  // --quantization; set once by main
double g_rrw_dps_rts = 0.0;       // --rate-random-walk; set once by main
double g_ramp_dps_s = 0.0;        // --rate-ramp; set once by main
bool g_reference =
    false;              // --reference 1: the orbit's 1 Hz, 5″ reference into the pipeline; set once by main
bool g_events = false;  // --events 1: each false alarm's event printed; set once by main

//! The unit of the sweep with n gyros: --unit's (its own N), else the seed's as-built unit cut or extended,
//! with --quantization's angle quantization on every gyro.
Calibration sweep_unit(int n) {
  if (g_unit) return *g_unit;
  Calibration cal = unit_with(n);
  if (g_quantization_deg == 0.0 && g_rrw_dps_rts == 0.0 && g_ramp_dps_s == 0.0) return cal;
  for (auto& g : cal.gyros) {
    if (!g.noise) g.noise = GyroNoise{};
    if (g_quantization_deg > 0.0) g.noise->quantization_deg = g_quantization_deg;
    if (g_rrw_dps_rts > 0.0) g.noise->rate_random_walk_dps_per_rts = g_rrw_dps_rts;
    if (g_ramp_dps_s > 0.0) g.noise->rate_ramp_dps_per_s = g_ramp_dps_s;
  }
  return cal;
}

RunOutcome run(int n, double duration_s, std::uint64_t seed, const std::vector<sim::FaultSpec>& faults) {
  RunOutcome out;
  auto sc = sim::builtin_scenario("orbit");
  if (!sc) return out;
  sc->unit = sweep_unit(n);
  sc->duration_s = duration_s;
  sc->rate_hz = kRateHz;
  sim::SimOptions so;
  so.seed = seed;
  so.faults = faults;
  auto simulator = sim::Simulator::create(*sc, so);
  if (!simulator) {
    std::fprintf(stderr, "simulator: %s\n", simulator.error().message.c_str());
    std::exit(1);
  }
  sim::SimEpoch se;
  if (!simulator->next(se)) return out;
  fdi::PipelineConfig config;
  config.false_alarm_probability = g_false_alarm_probability;
  config.initial_q_RB = se.truth_q_RB;
  auto pipeline = fdi::Pipeline::create(sc->unit, config);
  if (!pipeline) {
    std::fprintf(stderr, "pipeline: %s\n", pipeline.error().message.c_str());
    std::exit(1);
  }
  fdi::Epoch e;
  do {
    e.stamp_ns = se.stamp_ns;
    e.raw = se.raw_V;
    e.present = se.present;
    if (g_reference) e.reference_q_RB = se.reference_q_RB;
    for (const auto& ev : pipeline->step(e).events) {
      out.reference_rejections += ev.type == fdi::EventType::kReferenceRejected ? 1 : 0;
      out.noise_model += ev.type == fdi::EventType::kNoiseModel ? 1 : 0;
      if (ev.type != fdi::EventType::kDetected) continue;
      ++out.detections;
      ++out.by_test[static_cast<std::size_t>(ev.test)];
      if (g_events) out.detected_json.push_back(fdi::to_json(ev, n));
      out.own_level += ev.detail.find("own noise level") != std::string::npos ? 1 : 0;
      if (out.first_detected_s < 0.0) out.first_detected_s = ns_to_seconds(ev.stamp_ns);
    }
  } while (simulator->next(se));
  return out;
}

//! Runs `count` jobs over `threads` threads; job(i) must be thread-safe.
template <typename Job>
void parallel(int count, int threads, Job job) {
  std::atomic<int> next{0};
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (int i = next++; i < count; i = next++) job(i);
    });
  }
  for (auto& th : pool) th.join();
}

//! The full set's subset constants (k, h, parity columns) as the pipeline builds them.
struct Theory {
  int dof = 0;
  double k = 0.0;
  double h = 0.0;
  double s = 0.0;  //!< [σ] bias wander per parity axis
  double chi2_p = 0.0;
  double arl0 = 0.0;
  std::vector<double> w_norm;  //!< |w_i|·√T [σ per rad/s]
};

Theory theory(int n) {
  const Calibration cal = sweep_unit(n);
  fdi::PipelineConfig config;
  config.false_alarm_probability = g_false_alarm_probability;
  const auto constants = fdi::detail::gyro_constants(cal, config);
  Eigen::VectorXd arw(n);
  for (int i = 0; i < n; ++i) arw[i] = (*constants)[static_cast<std::size_t>(i)].arw_rad_rts;
  fdi::detail::SubsetCache cache(*GyroGeometry::create(cal.axes_B(), arw), Eigen::VectorXd::Zero(n), config,
                                 fdi::detail::detector_noise(cal, config));
  cache.prepare(1.0 / kRateHz);
  const auto& s = cache.get(all_gyros(n));
  Theory t{s.dof,
           s.cusum_k,
           s.cusum_h,
           s.bias_wander_sigma,
           fdi::allocated_probability(config, fdi::BudgetTest::kChi2),
           fdi::cusum_arl0_epochs(config),
           {}};
  for (int i = 0; i < n; ++i) t.w_norm.push_back(s.parity.col(i).norm() * cache.sqrt_period());
  return t;
}

//! [s] CUSUM delay of a step: ARL(δ − k) in epochs (Siegmund; Wald's (h + 1.166)/(δ − k) when large).
double step_delay_s(const Theory& t, double delta) {
  return fdi::cusum_arl(delta, t.k, t.h) / kRateHz;
}

//! [s] CUSUM delay of a ramp: the mean path S_n = max(0, S_{n−1} + c·n − k) reaching h.
double ramp_delay_s(const Theory& t, double c) {
  double s = 0.0;
  for (int n = 1; n < 10'000'000; ++n) {
    s = std::max(0.0, s + c * n - t.k);
    if (s > t.h) return n / kRateHz;
  }
  return INFINITY;
}

void false_alarm_sweep(int n, int hours, int run_hours, int jobs) {
  const int runs = std::max(1, hours / run_hours);
  hours = runs * run_hours;
  std::vector<int> detections(static_cast<std::size_t>(runs), 0);
  std::vector<int> rejections(static_cast<std::size_t>(runs), 0);
  std::vector<std::array<int, 7>> by_test(static_cast<std::size_t>(runs));
  std::vector<double> first_s(static_cast<std::size_t>(runs), -1.0);
  std::vector<int> noise_models(static_cast<std::size_t>(runs), 0);
  std::vector<std::vector<std::string>> events(static_cast<std::size_t>(runs));
  parallel(runs, jobs, [&](int i) {
    const RunOutcome o = run(n, 3600.0 * run_hours,
                             1000003ULL * static_cast<std::uint64_t>(n) + static_cast<std::uint64_t>(i), {});
    detections[static_cast<std::size_t>(i)] = o.detections;
    rejections[static_cast<std::size_t>(i)] = o.reference_rejections;
    by_test[static_cast<std::size_t>(i)] = o.by_test;
    first_s[static_cast<std::size_t>(i)] = o.first_detected_s;
    noise_models[static_cast<std::size_t>(i)] = o.noise_model;
    events[static_cast<std::size_t>(i)] = o.detected_json;
  });
  int total = 0;
  int runs_with = 0;
  for (int d : detections) {
    total += d;
    runs_with += d > 0 ? 1 : 0;
  }
  const Theory t = theory(n);
  const double epochs_per_1000h = 1000.0 * 3600.0 * kRateHz;
  const double design = epochs_per_1000h * (1.0 / t.arl0 + t.chi2_p);
  std::printf(
      "N=%d  %d h in %d-h runs: %d detections (%d runs)  %.2f per 1000 h  design %.2f  ratio %.2f  (d=%d "
      "k=%.3f h=%.2f s=%.3f)\n",
      n, hours, run_hours, total, runs_with, 1000.0 * total / hours, design, 1000.0 * total / hours / design,
      t.dof, t.k, t.h, t.s);
  std::array<int, 7> tests{};
  for (const auto& r : by_test)
    for (std::size_t j = 0; j < tests.size(); ++j) tests[j] += r[j];
  if (total > 0) {
    std::printf("N=%d  detections by test:", n);
    for (std::size_t j = 1; j < tests.size(); ++j)
      if (tests[j] > 0) std::printf(" %s %d", fdi::to_string(static_cast<fdi::DetectionTest>(j)), tests[j]);
    std::printf("; the first of a run at [h into it]:");
    for (double f : first_s)
      if (f >= 0.0) std::printf(" %.2f", f / 3600.0);
    std::printf("\n");
  }
  for (std::size_t i = 0; i < events.size(); ++i)
    for (const std::string& json : events[i]) std::printf("N=%d  run %zu: %s\n", n, i, json.c_str());
  int widened = 0;
  for (int w : noise_models) widened += w;
  if (widened > 0) std::printf("N=%d  noise_model events: %d\n", n, widened);
  if (g_reference) {
    int rejected = 0;
    for (int r : rejections) rejected += r;
    std::printf(
        "N=%d  %d h with the 1 Hz reference: %d reference rejections (design: %d tests at p = 1e-9 per "
        "sample)\n",
        n, hours, rejected, hours * 3600);
  }
  std::fflush(stdout);
}

void three_gyro_sweep(int hours, int jobs) {
  std::vector<RunOutcome> outcomes(static_cast<std::size_t>(hours));
  parallel(hours, jobs, [&](int i) {
    outcomes[static_cast<std::size_t>(i)] = run(3, 3600.0, 3000017ULL + static_cast<std::uint64_t>(i), {});
  });
  int total = 0;
  int own = 0;
  int rejected = 0;
  for (const RunOutcome& o : outcomes) {
    total += o.detections;
    own += o.own_level;
    rejected += o.reference_rejections;
  }
  std::printf(
      "N=3  %d h%s: %d detections (%d by a gyro's own noise level; design about 3e-10 per evaluation, 0.003 "
      "per 1000 h), %d reference rejections\n",
      hours, g_reference ? " with the 1 Hz reference" : "", total, own, rejected);
  std::fflush(stdout);
}

struct DelayCase {
  const char* name;
  sim::FaultKind kind;
  double size;
};

void delay_table(int n, int seeds, int jobs) {
  const DelayCase cases[] = {{"bias +1e-3 deg/s", sim::FaultKind::kBias, 1e-3},
                             {"bias +2e-4 deg/s", sim::FaultKind::kBias, 2e-4},
                             {"ramp 1e-5 deg/s2", sim::FaultKind::kRamp, 1e-5}};
  const Theory t = theory(n);
  constexpr double kAt = 120.0;
  for (const auto& c : cases) {
    for (int g = 1; g <= n; ++g) {
      std::vector<double> delay(static_cast<std::size_t>(seeds), -1.0);
      parallel(seeds, jobs, [&](int s) {
        sim::FaultSpec f;
        f.gyro = g;
        f.kind = c.kind;
        f.at_s = kAt;
        f.size = c.size;
        const auto r = run(n, kAt + 120.0, 7000ULL + static_cast<std::uint64_t>(s), {f});
        delay[static_cast<std::size_t>(s)] = r.first_detected_s < kAt ? -1.0 : r.first_detected_s - kAt;
      });
      double sum = 0.0;
      int count = 0;
      int early = 0;
      for (double d : delay) {
        if (d < 0.0) {
          ++early;
          continue;
        }
        sum += d;
        ++count;
      }
      const double wi = t.w_norm[static_cast<std::size_t>(g - 1)] * c.size * kDegToRad;
      const double th = c.kind == sim::FaultKind::kRamp ? ramp_delay_s(t, wi / kRateHz) : step_delay_s(t, wi);
      const double mean = count > 0 ? sum / count : NAN;
      std::printf("| %d | %s | %d | %.2f | %.2f | %.2f | %d/%d |\n", n, c.name, g, mean, th, mean / th, count,
                  seeds);
    }
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int hours = 1000;
  int jobs = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  int delay_seeds = 10;
  int three_gyro_hours = 0;
  int only_n = 0;  // --gyros: one N of the default unit
  int run_hours = 1;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--help" || arg == "-h") {
      std::printf(
          "fdi_sweep [--hours H] [--jobs J] [--delay-seeds S] [--arl0 EPOCHS] [--unit CAL.yaml]\n"
          "          [--quantization DEG] [--rate-random-walk K] [--rate-ramp R] [--run-hours L]\n"
          "          [--reference 1]\n"
          "  false alarms in H fault-free one-hour orbits per N = 4, 5, 6 (default 1000), then the "
          "detection\n"
          "  delays of the documented faults (S seeds per fault and gyro, default 10), on J threads.\n"
          "  --arl0: the CUSUM's design in-control ARL [epochs] (default 1e8; > 200): the budget's\n"
          "          false_alarm_probability becomes 1/(10 ARL0), every test scaled with it.\n"
          "  --unit: simulate and fuse this calibration file's unit instead (its own N only).\n"
          "  --quantization: angle quantization [deg] of every gyro of the default unit.\n"
          "  --rate-random-walk K [deg/s/sqrt(s)], --rate-ramp R [deg/s^2]: stated and simulated on every "
          "gyro\n"
          "          of the default unit (the ramp +R on each).\n"
          "  --run-hours L: H/L runs of L hours each (default 1).\n"
          "  --reference 1: feed the orbit's 1 Hz, 5\" reference too and count reference rejections.\n"
          "  --events 1: print each false alarm's detected event with its ledger rows (JSON).\n"
          "  --gyros N: the default unit with N gyros only (4, 5 or 6).\n");
      return 0;
    }
    if (a + 1 >= argc) {
      std::fprintf(stderr, "fdi_sweep: option %s needs a value\n", arg.c_str());
      return 2;
    }
    if (arg == "--arl0") {
      const double arl0 = std::atof(argv[++a]);
      const double share = fdi::kAllocations[static_cast<int>(fdi::BudgetTest::kCusum)].share;
      g_false_alarm_probability = 1.0 / (share * arl0);
      if (!(arl0 > 200.0) || !(g_false_alarm_probability < 0.5 / fdi::kLargestShare)) {
        std::fprintf(stderr, "fdi_sweep: option --arl0 must be > 200\n");
        return 2;
      }
      continue;
    }
    if (arg == "--quantization" || arg == "--rate-random-walk" || arg == "--rate-ramp") {
      const double v = std::atof(argv[++a]);
      if (!(v >= 0.0)) {
        std::fprintf(stderr, "fdi_sweep: option %s must be >= 0\n", arg.c_str());
        return 2;
      }
      if (arg == "--quantization") g_quantization_deg = v;
      if (arg == "--rate-random-walk") g_rrw_dps_rts = v;
      if (arg == "--rate-ramp") g_ramp_dps_s = v;
      continue;
    }
    if (arg == "--unit") {
      auto unit = read_calibration(argv[++a]);
      if (!unit) {
        std::fprintf(stderr, "%s\n", unit.error().message.c_str());
        return 2;
      }
      g_unit = *unit;
      continue;
    }
    const int value = std::atoi(argv[++a]);
    if (value < 0) {
      std::fprintf(stderr, "fdi_sweep: option %s must be >= 0\n", arg.c_str());
      return 2;
    }
    if (arg == "--hours") {
      hours = value;
    } else if (arg == "--jobs") {
      jobs = std::max(1, value);
    } else if (arg == "--delay-seeds") {
      delay_seeds = value;
    } else if (arg == "--reference") {
      g_reference = value != 0;
    } else if (arg == "--events") {
      g_events = value != 0;
    } else if (arg == "--gyros") {
      if (value < 4 || value > 6) {
        std::fprintf(stderr, "fdi_sweep: option --gyros must be 4, 5 or 6\n");
        return 2;
      }
      only_n = value;
    } else if (arg == "--run-hours") {
      run_hours = std::max(1, value);
    } else if (arg == "--three-gyro-hours") {
      three_gyro_hours = value;
    } else {
      std::fprintf(stderr, "fdi_sweep: unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  const int n_first = g_unit ? g_unit->gyro_count() : only_n > 0 ? only_n : 4;
  const int n_last = g_unit ? g_unit->gyro_count() : only_n > 0 ? only_n : 6;
  for (int n = n_first; n <= n_last && hours > 0; ++n) false_alarm_sweep(n, hours, run_hours, jobs);
  if (three_gyro_hours > 0) three_gyro_sweep(three_gyro_hours, jobs);
  if (delay_seeds > 0) {
    std::printf("\n| N | fault | gyro | mean delay [s] | theory [s] | ratio | detected after onset |\n");
    std::printf("|---|---|---|---|---|---|---|\n");
    for (int n = n_first; n <= n_last; ++n) delay_table(n, delay_seeds, jobs);
  }
  return 0;
}
