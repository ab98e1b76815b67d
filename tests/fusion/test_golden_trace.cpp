// Golden trace of the fusion pipeline: about twenty simulator scenarios (every fault kind, N = 3..6, with and
// without a reference, ground mode, operator commands) run straight into fdi::Pipeline, and a fingerprint of
// everything it says compared with the one checked in under tests/fusion/golden/:
//   - every event, every field (the statistic as a hexadecimal float, so bit for bit);
//   - every epoch's output, hashed bit for bit (64-bit FNV-1a over the bytes of each double: stamp,
//     quaternion, rate, per-axis sigma, mode, gyros used, and the health's parity residual, χ², CUSUM and
//     gyro states), one line per block of epochs with the block's last attitude printed in full;
//   - the final health (mode, gyros, counters).
// Any change of behaviour changes a line; the failure names the scenario and shows the first differing line,
// golden and now. When a change of behaviour is intended, re-bless (tests/fusion/golden/README.md):
//   TETRA_BLESS=1 build/tests/test_golden_trace      # rewrites tests/fusion/golden/*.trace
// and commit the new files with the reason in the message.
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "campaign.hpp"
#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/sim/simulator.hpp"
#include "units.hpp"

namespace tetra {
namespace {

using test::unit_with;

constexpr int kBlock = 100;  //!< epochs per hashed block

class Fnv {
 public:
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h_ ^= p[i];
      h_ *= 1099511628211ULL;
    }
  }
  void add(double v) { add(&v, sizeof v); }
  void add(std::int64_t v) { add(&v, sizeof v); }
  void add(std::uint64_t v) { add(&v, sizeof v); }
  std::uint64_t value() const { return h_; }
  void reset() { h_ = 14695981039346656037ULL; }

 private:
  std::uint64_t h_ = 14695981039346656037ULL;
};

enum class Op { kExclude, kReinstate, kReset };
struct OperatorCommand {
  double at_s = 0.0;
  Op op = Op::kExclude;
  int gyro = 0;
  bool force = false;  //!< exclude: even when the rest cannot determine the attitude
};

struct GoldenScenario {
  std::string name;
  sim::Scenario scenario;
  sim::SimOptions sim;
  fdi::PipelineConfig config;
  Calibration calibration;  //!< what the pipeline is told (default: the simulated unit itself)
  std::vector<OperatorCommand> commands;
};

// Failure messages name the scenario, not its bytes.
void PrintTo(const GoldenScenario& g, std::ostream* os) {
  *os << g.name;
}

sim::FaultSpec fault(int gyro, sim::FaultKind kind, double at, double size = 0.0,
                     std::optional<double> until = std::nullopt) {
  sim::FaultSpec f;
  f.gyro = gyro;
  f.kind = kind;
  f.at_s = at;
  f.size = size;
  f.until_s = until;
  return f;
}

GoldenScenario base(const std::string& name, const std::string& builtin, double duration_s, int n_gyros = 4,
                    double reference_hz = 0.0) {
  GoldenScenario g;
  g.name = name;
  auto sc = sim::builtin_scenario(builtin);
  EXPECT_TRUE(sc.ok()) << builtin;
  g.scenario = *sc;
  g.scenario.duration_s = duration_s;
  g.scenario.unit = test::unit_with(n_gyros);
  g.scenario.reference.rate_hz = reference_hz;
  if (reference_hz > 0.0) g.scenario.reference.noise_arcsec = 5.0;
  if (builtin == "orbit" || builtin == "slews") {
    g.scenario.motion.acs.amplitude_deg = 0.04;
    g.scenario.motion.acs.peak_accel_dps2 = 1e-4;
    g.config.max_angular_acceleration_dps2 = 2e-4;
  }
  g.calibration = g.scenario.unit;
  g.sim.seed = 11;
  return g;
}

std::vector<GoldenScenario> scenarios() {
  using K = sim::FaultKind;
  std::vector<GoldenScenario> all;
  auto add = [&](GoldenScenario g, std::vector<sim::FaultSpec> faults = {}) {
    g.sim.faults = std::move(faults);
    all.push_back(std::move(g));
  };
  add(base("orbit_nominal", "orbit", 600.0));
  add(base("orbit_reference_nominal", "orbit", 300.0, 4, 1.0));
  add(base("bias_step", "orbit", 120.0), {fault(2, K::kBias, 60.0, 1e-3)});
  add(base("bias_small", "orbit", 150.0), {fault(1, K::kBias, 40.0, 2e-4)});
  add(base("ramp", "orbit", 200.0), {fault(4, K::kRamp, 50.0, 1e-5)});
  add(base("stuck", "orbit", 90.0), {fault(3, K::kStuck, 60.0)});
  add(base("zero", "orbit", 90.0), {fault(4, K::kZero, 60.0)});
  add(base("noise", "orbit", 120.0), {fault(2, K::kNoise, 60.0, 10.0)});
  add(base("spikes", "orbit", 150.0), {fault(1, K::kSpike, 30.0, 0.05), fault(1, K::kSpike, 45.0, 0.05),
                                       fault(1, K::kSpike, 60.0, 0.05), fault(1, K::kSpike, 75.0, 0.05)});
  add(base("dropout", "orbit", 90.0), {fault(3, K::kDropout, 60.0)});
  add(base("invalid_transient", "orbit", 90.0), {fault(2, K::kInvalid, 60.0, 0.0, 60.5)});
  add(base("invalid", "orbit", 90.0), {fault(2, K::kInvalid, 60.0)});
  add(base("reference_bias", "orbit", 300.0, 4, 1.0), {fault(3, K::kBias, 60.0, 3e-4)});
  add(base("reference_ramp", "orbit", 300.0, 4, 1.0), {fault(2, K::kRamp, 60.0, 2e-5)});
  {
    GoldenScenario g = base("slew_scale_reference", "slews", 220.0, 4, 1.0);
    g.scenario.motion.slews = {{Eigen::Vector3d(0.0, 0.6, 0.8), 30.0, 80.0, 60.0}};
    g.config.max_angular_acceleration_dps2 = 0.05;
    add(g, {fault(1, K::kScale, 60.0, 0.05)});
  }
  {
    GoldenScenario g = base("slew_fault_free", "slews", 200.0);
    g.scenario.motion.slews = {{Eigen::Vector3d::UnitZ(), 20.0, 30.0, 40.0},
                               {Eigen::Vector3d::UnitX(), -15.0, 110.0, 30.0}};
    g.config.max_angular_acceleration_dps2 = 0.05;
    add(g);
  }
  add(base("n3_stuck", "orbit", 90.0, 3), {fault(2, K::kStuck, 60.0)});
  add(base("n5_bias_glt", "orbit", 150.0, 5), {fault(5, K::kBias, 60.0, 4e-4)});
  add(base("n5_reference_ramp", "orbit", 200.0, 5, 1.0), {fault(3, K::kRamp, 60.0, 2e-5)});
  add(base("n6_bias_then_stuck", "orbit", 200.0, 6),
      {fault(4, K::kBias, 50.0, 5e-4), fault(6, K::kStuck, 120.0)});
  {
    GoldenScenario g = base("ground_lab_orbit", "lab-orbit", 1200.0);
    g.config.latitude_deg = -23.2;
    add(g);
  }
  {
    GoldenScenario g = base("ground_factory_calibration", "lab-orbit", 300.0);
    g.config.latitude_deg = -23.2;
    auto factory = read_calibration(test::source_path("examples/factory.yaml"));
    EXPECT_TRUE(factory.ok());
    if (factory) g.calibration = *factory;
    add(g);
  }
  {
    GoldenScenario g = base("operator_commands", "orbit", 200.0);
    // Gyro 2 out, a gyro that does not exist, gyro 1 refused (gyros 3 and 4 alone cannot determine the
    // attitude), gyro 3 forced out (LOST), gyro 2 back, again (not excluded), reset.
    g.commands = {{20.0, Op::kExclude, 2},       {40.0, Op::kExclude, 7},   {50.0, Op::kExclude, 1},
                  {60.0, Op::kExclude, 3, true}, {80.0, Op::kReinstate, 2}, {90.0, Op::kReinstate, 2},
                  {120.0, Op::kReset, 0}};
    add(g, {fault(1, K::kStuck, 150.0)});
  }
  {
    GoldenScenario g = base("jitter_drops", "orbit", 300.0);
    g.scenario.jitter_s = 0.01;
    g.scenario.drop_probability = 0.01;
    g.config.sample_period_s = 0.1;
    add(g, {fault(4, K::kBias, 150.0, 1e-3)});
  }
  return all;
}

std::string hexfloat(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%a", v);
  return text;
}

std::string full(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string event_line(const fdi::FdiEvent& e, std::int64_t epoch) {
  std::ostringstream s;
  s << "E " << epoch << " " << e.stamp_ns << " " << fdi::to_string(e.type)
    << " gyro=" << (e.gyro ? std::to_string(*e.gyro) : "-") << " test=" << fdi::to_string(e.test)
    << " statistic=" << hexfloat(e.statistic) << " kind=" << fdi::to_string(e.kind)
    << " evidence=" << fdi::to_string(e.evidence) << " gyros=" << e.gyros << " detail=" << e.detail;
  return s.str();
}

void hash_epoch(Fnv& h, const fdi::StepResult& r, const fdi::Health& health) {
  h.add(static_cast<std::uint64_t>(r.accepted));
  if (r.accepted) {
    const auto& a = r.attitude;
    h.add(a.stamp_ns);
    h.add(a.q_RB.w());
    h.add(a.q_RB.x());
    h.add(a.q_RB.y());
    h.add(a.q_RB.z());
    for (int i = 0; i < 3; ++i) h.add(a.omega_BR_B_rad_s[i]);
    for (int i = 0; i < 3; ++i) h.add(a.sigma_rad[i]);
    h.add(static_cast<std::uint64_t>(a.mode));
    h.add(static_cast<std::uint64_t>(a.gyros));
  }
  h.add(health.parity_residual);
  h.add(health.chi2);
  h.add(health.cusum);
  h.add(health.chi2_threshold);
  h.add(health.cusum_threshold);
  h.add(static_cast<std::uint64_t>(health.mode));
  for (const auto& g : health.gyros) {
    h.add(static_cast<std::uint64_t>(g.state));
    h.add(static_cast<std::uint64_t>(g.kind));
  }
}

std::string block_line(std::int64_t block, const Fnv& h, const fdi::AttitudeEstimate& a) {
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016" PRIx64, h.value());
  return "B " + std::to_string(block) + " " + hash + " t_ns=" + std::to_string(a.stamp_ns) +
         " q=" + full(a.q_RB.w()) + "," + full(a.q_RB.x()) + "," + full(a.q_RB.y()) + "," + full(a.q_RB.z()) +
         " sigma_rad=" + full(a.sigma_rad[0]) + "," + full(a.sigma_rad[1]) + "," + full(a.sigma_rad[2]) +
         " mode=" + fdi::to_string(a.mode) + " gyros=" + std::to_string(a.gyros);
}

std::string health_line(const fdi::Health& h) {
  const auto& c = h.counters;
  std::string s =
      "H mode=" + std::string(fdi::to_string(h.mode)) + " used=" + std::to_string(h.used) + " states=";
  for (const auto& g : h.gyros)
    s += std::string(fdi::to_string(g.state)) + "/" + fdi::to_string(g.kind) + ",";
  s += " accepted=" + std::to_string(c.epochs_accepted) +
       " rejected_time=" + std::to_string(c.epochs_rejected_time) +
       " rejected_shape=" + std::to_string(c.epochs_rejected_shape) +
       " samples=" + std::to_string(c.samples_accepted) + " invalid=" + std::to_string(c.samples_invalid) +
       " absent=" + std::to_string(c.samples_absent) + " outliers=" + std::to_string(c.samples_outlier) +
       " spikes=" + std::to_string(c.spikes);
  return s;
}

//! Applies an operator command; returns its acknowledgement.
fdi::FdiEvent apply(fdi::Pipeline& p, const OperatorCommand& c, std::int64_t stamp_ns) {
  switch (c.op) {
    case Op::kExclude:
      return p.exclude(c.gyro, stamp_ns, c.force);
    case Op::kReinstate:
      return p.reinstate(c.gyro, stamp_ns);
    case Op::kReset:
      break;
  }
  return p.reset_command(stamp_ns);
}

//! Steps `p` through the whole of scenario `g`, its commands included, and discards what it returns.
std::string run_through(fdi::Pipeline& p, const GoldenScenario& g) {
  auto simulator = sim::Simulator::create(g.scenario, g.sim);
  if (!simulator) return "simulator: " + simulator.error().message;
  sim::SimEpoch se;
  fdi::Epoch e;
  std::size_t next_command = 0;
  while (simulator->next(se)) {
    while (next_command < g.commands.size() && g.commands[next_command].at_s <= se.time_s)
      apply(p, g.commands[next_command++], se.stamp_ns);
    e.stamp_ns = se.stamp_ns;
    e.raw = se.raw_V;
    e.present = se.present;
    e.reference_q_RB = se.reference_q_RB;
    p.step(e);
  }
  return {};
}

//! The trace of one scenario, one line per event, per block of epochs, and the final health. With
//! `reset_first`, of a pipeline that ran the scenario once before and was then reset().
std::vector<std::string> trace(const GoldenScenario& g, bool reset_first = false) {
  std::vector<std::string> lines{"# " + g.name};
  auto simulator = sim::Simulator::create(g.scenario, g.sim);
  if (!simulator) return {"simulator: " + simulator.error().message};
  sim::SimEpoch se;
  if (!simulator->next(se)) return {"simulator: no epoch"};
  fdi::PipelineConfig config = g.config;
  config.initial_q_RB = se.truth_q_RB;
  auto pipeline = fdi::Pipeline::create(g.calibration, config);
  if (!pipeline) return {"pipeline: " + pipeline.error().message};
  if (reset_first) {
    if (auto error = run_through(*pipeline, g); !error.empty()) return {error};
    pipeline->reset();
  }
  fdi::Epoch e;
  std::size_t next_command = 0;
  std::int64_t index = 0;
  Fnv h;
  fdi::AttitudeEstimate last;
  do {
    while (next_command < g.commands.size() && g.commands[next_command].at_s <= se.time_s)
      lines.push_back("C" +
                      event_line(apply(*pipeline, g.commands[next_command++], se.stamp_ns), index).substr(1));
    e.stamp_ns = se.stamp_ns;
    e.raw = se.raw_V;
    e.present = se.present;
    e.reference_q_RB = se.reference_q_RB;
    const auto& r = pipeline->step(e);
    for (const auto& ev : r.events) {
      lines.push_back(event_line(ev, index));
      // Each isolation is rebuilt from its event alone: the arbiter's rule over its ledger rows names its
      // gyro.
      if (ev.type == fdi::EventType::kIsolated && fdi::ruling_of(ev) != ev.gyro.value_or(0))
        lines.push_back("ARBITER: the ledger of this isolation names gyro " +
                        std::to_string(fdi::ruling_of(ev)));
    }
    hash_epoch(h, r, pipeline->health());
    if (r.accepted) last = r.attitude;
    if (++index % kBlock == 0) {
      lines.push_back(block_line(index / kBlock - 1, h, last));
      h.reset();
    }
  } while (simulator->next(se));
  if (index % kBlock != 0) lines.push_back(block_line(index / kBlock, h, last));
  lines.push_back(health_line(pipeline->health()));
  // Every source's finding is one the rule confirms from its rows (the arbiter refused none).
  if (pipeline->arbiter_refusals() != 0)
    lines.push_back("ARBITER: refused " + std::to_string(pipeline->arbiter_refusals()) + " findings");
  return lines;
}

std::string golden_path(const std::string& name) {
  return test::source_path("tests/fusion/golden/" + name + ".trace");
}

std::vector<std::string> read_lines(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

bool blessing() {
  const char* v = std::getenv("TETRA_BLESS");
  return v != nullptr && std::strcmp(v, "1") == 0;
}

class GoldenTrace : public ::testing::TestWithParam<GoldenScenario> {};

TEST_P(GoldenTrace, MatchesTheCheckedInTrace) {
  const GoldenScenario& g = GetParam();
  const std::vector<std::string> now = trace(g);
  const std::string path = golden_path(g.name);
  if (blessing()) {
    std::ofstream out(path);
    for (const auto& line : now) out << line << "\n";
    ASSERT_TRUE(out.good()) << "cannot write " << path;
    std::printf("blessed %s (%zu lines)\n", path.c_str(), now.size());
    return;
  }
  const std::vector<std::string> golden = read_lines(path);
  ASSERT_FALSE(golden.empty()) << path << " is missing: TETRA_BLESS=1 "
                               << "writes it";
  const std::size_t n = std::min(golden.size(), now.size());
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(golden[i], now[i]) << "scenario " << g.name << ": first difference at line " << i + 1 << " of "
                                 << path << "\n  golden: " << golden[i] << "\n  now:    " << now[i];
  }
  ASSERT_EQ(golden.size(), now.size()) << "scenario " << g.name << ": "
                                       << (golden.size() > n ? "golden has more lines, first: " + golden[n]
                                                             : "now has more lines, first: " + now[n]);
}

INSTANTIATE_TEST_SUITE_P(Scenarios, GoldenTrace, ::testing::ValuesIn(scenarios()),
                         [](const ::testing::TestParamInfo<GoldenScenario>& param_info) {
                           return param_info.param.name;
                         });

TEST_P(GoldenTrace, IsTheSameAfterAResetAsFromTheStart) {
  // reset() promises the initial state: a pipeline that ran the scenario once (its episodes, exclusions,
  // learned noise, reference history, clock) and was reset must give the fresh pipeline's trace, every bit.
  const GoldenScenario& g = GetParam();
  const auto fresh = trace(g), reset = trace(g, true);
  std::size_t i = 0;
  while (i < fresh.size() && i < reset.size() && fresh[i] == reset[i]) ++i;
  EXPECT_TRUE(i == fresh.size() && i == reset.size()) << g.name << ": first difference at line " << i + 1
                                                      << "\n  fresh: " << (i < fresh.size() ? fresh[i] : "")
                                                      << "\n  reset: " << (i < reset.size() ? reset[i] : "");
}

TEST(GoldenTrace, SeesTheLastBitOfOneSample) {
  // The gate must see a change that no tolerance-based test would: gyro 1's bias one ulp off changes the last
  // bit of its calibrated rate, and the trace must differ (the block hashes take every bit of every output).
  GoldenScenario g = scenarios().front();
  const auto before = trace(g);
  g.calibration.gyros[0].bias_V = std::nextafter(g.calibration.gyros[0].bias_V, 1.0);
  EXPECT_NE(before, trace(g));
}

TEST(GoldenTrace, CoversEveryFaultKindAndPackageSize) {
  // The gate is only as good as its coverage: every simulator fault kind, N = 3..6, a reference, ground mode
  // and operator commands each appear in at least one scenario.
  std::set<sim::FaultKind> kinds;
  std::set<int> sizes;
  bool reference = false, ground = false, commands = false;
  for (const auto& g : scenarios()) {
    for (const auto& f : g.sim.faults) kinds.insert(f.kind);
    sizes.insert(g.scenario.unit.gyro_count());
    reference = reference || g.scenario.reference.rate_hz > 0.0;
    ground = ground || g.config.latitude_deg.has_value();
    commands = commands || !g.commands.empty();
  }
  EXPECT_EQ(kinds.size(), 9U);
  EXPECT_EQ(sizes, (std::set<int>{3, 4, 5, 6}));
  EXPECT_TRUE(reference && ground && commands);
}

}  // namespace
}  // namespace tetra
