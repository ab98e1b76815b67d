// tetra sim SCENARIO — simulated gyro data with known truth (see docs/sim.md).
#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/sim/turntable.hpp"

namespace tetra::cli {

namespace {

constexpr const char* kName = "sim";

int run_turntable(const std::string& unit_path, const sim::TurntablePlan& plan, std::uint64_t seed,
                  const std::string& out_path) {
  Calibration unit = seed_as_built_unit();
  if (!unit_path.empty()) {
    auto read = read_calibration(unit_path);
    if (!read) return report(kName, read.error());
    unit = std::move(read.value());
  }
  auto log = sim::simulate_turntable(unit, plan, seed);
  if (!log) return report(kName, log.error());
  if (out_path.empty() || out_path == "-") {
    std::cout << format_turntable_log(*log);
  } else if (Status st = write_turntable_log(out_path, *log); !st) {
    return report(kName, st.error());
  }
  std::cerr << "tetra sim: turntable: " << log->rows() << " rows, " << unit.gyro_count() << " gyros"
            << (out_path.empty() || out_path == "-" ? std::string() : " -> " + out_path) << '\n';
  return kExitOk;
}

}  // namespace

int cmd_sim(int argc, char** argv) {
  CLI::App app{"Simulate a gyro unit with known truth: turntable calibration plan (more scenarios below).",
               kName};
  std::string scenario;
  std::uint64_t seed = 1;
  std::string unit_path;
  std::string out_path;
  sim::TurntablePlan plan;
  app.add_option("SCENARIO", scenario, "turntable")->required();
  app.add_option("--seed", seed, "random seed; the same seed gives byte-identical output")
      ->capture_default_str();
  app.add_option(
      "--unit", unit_path,
      "calibration YAML of the simulated unit (the as-built truth); default: the seed paper's unit");
  app.add_option("--out,-o", out_path, "output file (default: standard output)");
  app.add_option("--rate-hz", plan.rate_hz, "[Hz] sampling rate")->capture_default_str();
  app.add_option("--latitude", plan.latitude_deg, "[deg] geodetic latitude of the table")
      ->capture_default_str();
  app.add_option("--table-rate", plan.table_rate_dps, "[deg/s] turntable: gimbal rate")
      ->capture_default_str();
  app.add_option("--revolutions", plan.revolutions, "turntable: revolutions per sequence")
      ->capture_default_str();
  app.add_option("--order", plan.order,
                 "turntable: sequence numbers in the order run, e.g. 1,2,5,6 (default 1..16)")
      ->delimiter(',');
  app.add_flag("--wrap", plan.wrap_angles, "turntable: write encoder angles wrapped to (-180, 180]");
  if (auto status = parse(app, argc, argv)) return *status;

  if (scenario == "turntable") return run_turntable(unit_path, plan, seed, out_path);
  return report(kName, bad_input("unknown scenario '" + scenario + "' (known: turntable)"));
}

}  // namespace tetra::cli
