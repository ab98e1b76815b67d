// tetra sim SCENARIO — simulated gyro data with known truth (see docs/sim.md).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "sim_closed_loop.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"
#include "tetra/sim/turntable.hpp"
#if TETRA_WITH_DDS
#include "sim_dds.hpp"
#include "sim_dds_loop.hpp"
#endif

namespace tetra::cli {

namespace {

constexpr const char* kName = "sim";

void print_progress(double fraction) {
  std::cerr << "tetra sim: " << std::lround(fraction * 100.0) << " %\n";
}

int run_turntable(const Calibration& unit, const sim::TurntablePlan& plan, const sim::GyroModelOptions& model,
                  std::uint64_t seed, RunFiles& files, OutputFile& out) {
  auto log = sim::simulate_turntable(unit, plan, seed, model);
  if (!log) return report(kName, log.error());
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  log->metadata.insert(log->metadata.end(), meta.begin(), meta.end());
  if (Status st = out.write(format_turntable_log(*log)); !st) return report(kName, st.error());
  if (Status st = files.commit(); !st) return report(kName, st.error());
  std::cerr << "tetra sim: turntable: " << log->rows() << " rows, " << unit.gyro_count() << " gyros"
            << (out.path() == "-" ? std::string() : " -> " + out.path()) << '\n';
  return kExitOk;
}

bool looks_like_file(const std::string& scenario) {
  const auto ext = std::filesystem::path(scenario).extension().string();
  return ext == ".yaml" || ext == ".yml" || std::filesystem::exists(scenario);
}

}  // namespace

int cmd_sim(int argc, char** argv) {
  CLI::App app{
      "Simulate a gyro unit with known truth. SCENARIO: turntable, static, lab-orbit, orbit, slews, or a "
      "scenario YAML file (docs/sim.md). Options given here override the scenario's.",
      kName};
  std::string scenario_name;
  std::uint64_t seed = 1;
  std::string unit_path;
  std::string out_path;
  std::string truth_path;
  std::vector<std::string> fault_texts;
  double rate_hz = 0.0;
  double minutes = 0.0;
  double latitude_deg = 0.0;
  double reference_hz = 0.0;
  double reference_noise_arcsec = 0.0;
  double acs_amplitude_deg = 0.0;
  double acs_accel_dps2 = 0.0;
  double jitter_s = 0.0;
  double drop_probability = 0.0;
  double range_dps = 0.0;
  double orbit_period_min = 0.0;
  sim::TurntablePlan plan;
  app.add_option("SCENARIO", scenario_name, "turntable | static | lab-orbit | orbit | slews | FILE.yaml")
      ->required();
  app.add_option("--seed", seed, "random seed; the same seed gives byte-identical output")
      ->capture_default_str();
  app.add_option("--unit", unit_path,
                 "calibration YAML of the simulated unit (the as-built truth, with its noise: sections); "
                 "default: the seed paper's unit");
  app.add_option(
      "--out,-o", out_path,
      "output log: CSV, or HDF5 when named .h5 (- = standard output, CSV only; turntable: CSV, the "
      "default)");
  app.add_option("--truth", truth_path, "truth file: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps");
  auto* opt_rate =
      app.add_option("--rate-hz", rate_hz, "[Hz] gyro sampling rate")->check(CLI::PositiveNumber);
  auto* opt_minutes =
      app.add_option("--minutes", minutes, "[min] duration (not for turntable)")->check(CLI::PositiveNumber);
  auto* opt_lat =
      app.add_option("--latitude", latitude_deg, "[deg] geodetic latitude (turntable, static, lab-orbit)")
          ->check(CLI::Range(-90.0, 90.0));
  app.add_option("--fault", fault_texts,
                 "gyro=N,kind=K,at=S[,size=X][,until=S] (repeatable; docs/interfaces.md §2.7)");
  auto* opt_ref = app.add_option("--reference-hz", reference_hz, "[Hz] attitude reference rate (0 = none)")
                      ->check(CLI::NonNegativeNumber);
  auto* opt_ref_noise =
      app.add_option("--reference-noise", reference_noise_arcsec, "[arcsec] reference 1-sigma per axis")
          ->check(CLI::NonNegativeNumber);
  auto* opt_acs_amp = app.add_option("--acs-amplitude", acs_amplitude_deg,
                                     "[deg] orbit/slews: attitude-control motion amplitude (0 = none)");
  auto* opt_acs_acc =
      app.add_option("--acs-accel", acs_accel_dps2, "[deg/s^2] orbit/slews: its peak acceleration")
          ->check(CLI::PositiveNumber);
  auto* opt_period =
      app.add_option("--orbit-period", orbit_period_min, "[min] orbit/slews: orbit period (one pitch turn)")
          ->check(CLI::PositiveNumber);
  auto* opt_jitter = app.add_option("--jitter", jitter_s, "[s] sample-time jitter, uniform +-")
                         ->check(CLI::NonNegativeNumber);
  auto* opt_drop =
      app.add_option("--drop", drop_probability, "probability that a gyro sample is not delivered")
          ->check(CLI::Range(0.0, 1.0));
  auto* opt_range = app.add_option("--range", range_dps, "[deg/s] measuring range (saturation)")
                        ->check(CLI::PositiveNumber);
  auto* opt_table = app.add_option("--table-rate", plan.table_rate_dps, "[deg/s] turntable: gimbal rate")
                        ->capture_default_str();
  auto* opt_revs = app.add_option("--revolutions", plan.revolutions, "turntable: revolutions per sequence")
                       ->capture_default_str();
  auto* opt_order =
      app.add_option("--order", plan.order,
                     "turntable: sequence numbers in the order run, e.g. 1,2,5,6 (default 1..16)")
          ->delimiter(',');
  auto* opt_wrap =
      app.add_flag("--wrap", plan.wrap_angles, "turntable: write encoder angles wrapped to (-180, 180]");
  ClosedLoopCliOptions loop_options;
  add_closed_loop_options(app, loop_options);
#if TETRA_WITH_DDS
  SimDdsOptions dds_options;
  add_sim_dds_options(app, dds_options);
#endif
  if (auto status = parse(app, argc, argv)) return *status;

  RunFiles files;
  if (!unit_path.empty()) files.add_input(unit_path, "--unit");
  if (looks_like_file(scenario_name)) files.add_input(scenario_name, "SCENARIO");
  if (scenario_name == "turntable" && out_path.empty()) out_path = "-";
  OutputFile* log_out = nullptr;
  OutputFile* truth_out = nullptr;
  if (!out_path.empty()) {
    auto out = files.add(out_path, "--out");
    if (!out) return report(kName, out.error());
    log_out = *out;
  }
  if (!truth_path.empty() && scenario_name != "turntable") {
    auto out = files.add(truth_path, "--truth");
    if (!out) return report(kName, out.error());
    truth_out = *out;
  }

  std::optional<Calibration> unit;
  if (!unit_path.empty()) {
    auto read = read_calibration(unit_path);
    if (!read) return report(kName, read.error());
    unit = std::move(read.value());
  }

  if (scenario_name == "turntable") {
    for (const CLI::Option* o :
         {opt_minutes, opt_ref, opt_ref_noise, opt_acs_amp, opt_acs_acc, opt_period, opt_jitter, opt_drop}) {
      if (o->count()) return report(kName, bad_input("turntable: " + o->get_name() + " does not apply"));
    }
    if (!fault_texts.empty() || !truth_path.empty()) {
      return report(kName, bad_input("turntable: --fault and --truth do not apply"));
    }
    if (opt_rate->count()) plan.rate_hz = rate_hz;
    if (opt_lat->count()) plan.latitude_deg = latitude_deg;
    sim::GyroModelOptions model;
    if (opt_range->count()) model.range_dps = range_dps;
    return run_turntable(unit ? *unit : seed_as_built_unit(), plan, model, seed, files, *log_out);
  }

  for (const CLI::Option* o : {opt_table, opt_revs, opt_order, opt_wrap}) {
    if (o->count())
      return report(kName, bad_input(o->get_name() + " applies to the turntable scenario only"));
  }
  Result<sim::Scenario> scenario = looks_like_file(scenario_name) ? sim::read_scenario(scenario_name)
                                                                  : sim::builtin_scenario(scenario_name);
  if (!scenario) return report(kName, scenario.error());
  sim::Scenario& sc = scenario.value();
  if (unit) sc.unit = *unit;
  if (opt_rate->count()) sc.rate_hz = rate_hz;
  if (opt_minutes->count()) sc.duration_s = minutes * 60.0;
  if (opt_lat->count()) sc.motion.latitude_deg = latitude_deg;
  if (opt_ref->count()) sc.reference.rate_hz = reference_hz;
  if (opt_ref_noise->count()) sc.reference.noise_arcsec = reference_noise_arcsec;
  if (opt_acs_amp->count()) sc.motion.acs.amplitude_deg = acs_amplitude_deg;
  if (opt_acs_acc->count()) sc.motion.acs.peak_accel_dps2 = acs_accel_dps2;
  if (opt_period->count()) sc.motion.orbit_period_s = orbit_period_min * 60.0;
  if (opt_jitter->count()) sc.jitter_s = jitter_s;
  if (opt_drop->count()) sc.drop_probability = drop_probability;
  if (opt_range->count()) sc.model.range_dps = range_dps;

  sim::SimOptions options;
  options.seed = seed;
  for (const std::string& text : fault_texts) {
    auto fault = sim::parse_fault_spec(text);
    if (!fault) return report(kName, fault.error());
    options.faults.push_back(fault.value());
  }
  if (loop_options.enabled && (!out_path.empty() || !truth_path.empty())) {
    return report(kName, bad_input("--out and --truth do not apply with --closed-loop (see --pointing)"));
  }
#if TETRA_WITH_DDS
  if (loop_options.enabled && dds_options.enabled)
    return sim_dds_closed_loop_main(sc, options, loop_options, dds_options);
#endif
  if (loop_options.enabled) return sim_closed_loop_main(sc, options, loop_options);
#if TETRA_WITH_DDS
  if (dds_options.enabled) {
    auto simulator = sim::Simulator::create(sc, options);
    if (!simulator) return report(kName, simulator.error());
    return sim_dds_main(*simulator, dds_options);
  }
#endif
  if (log_out == nullptr) return report(kName, bad_input("--out LOG.csv is required (or --dds)"));

  auto simulator = sim::Simulator::create(sc, options);
  if (!simulator) return report(kName, simulator.error());
  const bool long_run = simulator->epoch_count() > 2'000'000;
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status st =
          sim::write_simulation(*simulator, *log_out, truth_out, meta, long_run ? print_progress : nullptr);
      !st) {
    return report(kName, st.error());
  }
  if (Status st = files.commit(); !st) return report(kName, st.error());
  std::cerr << "tetra sim: " << sc.name << ": " << simulator->epoch_count() << " epochs, "
            << simulator->gyro_count() << " gyros -> " << out_path
            << (truth_path.empty() ? std::string() : ", truth -> " + truth_path) << '\n';
  return kExitOk;
}

}  // namespace tetra::cli
