// tetra sim SCENARIO — simulated gyro data with known truth (see docs/sim.md).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <optional>
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

constexpr const char* kSimName = "sim";

void print_progress(double fraction) {
  std::cerr << "tetra sim: " << std::lround(fraction * 100.0) << " %\n";
}

// Options that override the scenario's values; each pointer tells whether its option was given.
struct ScenarioOverrides {
  double rate_hz = 0.0;
  double minutes = 0.0;
  double latitude_deg = 0.0;
  double reference_hz = 0.0;
  double reference_noise_arcsec = 0.0;
  double reference_latency_s = 0.0;
  std::vector<double> reference_bias;   // arcsec, at s, ramp s
  std::vector<double> reference_misid;  // deg, at s, duration s
  double acs_amplitude_deg = 0.0;
  double acs_accel_dps2 = 0.0;
  double jitter_s = 0.0;
  double drop_probability = 0.0;
  double range_dps = 0.0;
  double orbit_period_min = 0.0;
  CLI::Option* rate = nullptr;
  CLI::Option* minutes_given = nullptr;
  CLI::Option* latitude = nullptr;
  CLI::Option* reference = nullptr;
  CLI::Option* reference_noise = nullptr;
  CLI::Option* reference_latency = nullptr;
  CLI::Option* reference_bias_given = nullptr;
  CLI::Option* reference_misid_given = nullptr;
  CLI::Option* acs_amplitude = nullptr;
  CLI::Option* acs_accel = nullptr;
  CLI::Option* period = nullptr;
  CLI::Option* jitter = nullptr;
  CLI::Option* drop = nullptr;
  CLI::Option* range = nullptr;
};

struct SimArgs {
  std::string scenario_name;
  std::uint64_t seed = 1;
  std::string unit_path;
  std::string out_path;
  std::string truth_path;
  std::string write_unit_path;           // --write-unit: the simulated unit as a calibration YAML, then stop
  std::vector<std::string> fault_texts;  // --fault: replace the scenario's faults
  std::vector<std::string> add_fault_texts;  // --add-fault: added to the scenario's faults
  ScenarioOverrides over;
  sim::TurntablePlan plan;
  std::vector<CLI::Option*> turntable_only;  // --table-rate, --revolutions, --order, --wrap
  ClosedLoopCliOptions loop;
#if TETRA_WITH_DDS
  SimDdsOptions dds;
#endif
};

void add_run_options(CLI::App& app, SimArgs& a) {
  app.add_option("SCENARIO", a.scenario_name, "turntable | static | lab-orbit | orbit | slews | FILE.yaml");
  app.add_option("--write-unit", a.write_unit_path,
                 "write the simulated unit (the seed paper's as-built unit, or --unit's) as a calibration "
                 "YAML to FILE and stop (no SCENARIO)");
  app.add_option("--seed", a.seed, "random seed; the same seed gives byte-identical output")
      ->capture_default_str();
  app.add_option("--unit", a.unit_path,
                 "calibration YAML of the simulated unit (the as-built truth, with its noise: sections); "
                 "default: the seed paper's unit");
  app.add_option(
      "--out,-o", a.out_path,
      "output log: CSV, or HDF5 when named .h5 (- = standard output, CSV only; turntable: CSV, the default)");
  app.add_option("--truth", a.truth_path, "truth file: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps");
}

void add_scenario_options(CLI::App& app, SimArgs& a) {
  ScenarioOverrides& o = a.over;
  // The ranges are the scenario keys' (docs/sim.md, "Ranges"), checked here to name the option.
  o.rate = app.add_option("--rate-hz", o.rate_hz, "[Hz] gyro sampling rate")
               ->check(number_in(0.0, sim::kMaxRate_hz, true));
  o.minutes_given = app.add_option("--minutes", o.minutes, "[min] duration (not for turntable)")
                        ->check(number_in(0.0, sim::kMaxDuration_s / 60.0, true));
  o.latitude =
      app.add_option("--latitude", o.latitude_deg, "[deg] geodetic latitude (turntable, static, lab-orbit)")
          ->check(CLI::Range(-90.0, 90.0));
  app.add_option("--fault", a.fault_texts,
                 "gyro=N,kind=K,at=S[,size=X][,until=S] (repeatable; docs/interfaces.md §2.7); replaces "
                 "the scenario file's faults");
  app.add_option("--add-fault", a.add_fault_texts,
                 "a fault added to the scenario file's faults (and to --fault's), same syntax; repeatable");
  o.reference = app.add_option("--reference-hz", o.reference_hz, "[Hz] attitude reference rate (0 = none)")
                    ->check(CLI::NonNegativeNumber);
  o.reference_noise =
      app.add_option("--reference-noise", o.reference_noise_arcsec, "[arcsec] reference 1-sigma per axis")
          ->check(number_in(0.0, sim::kMaxReferenceNoise_arcsec));
  o.reference_latency =
      app.add_option("--reference-latency", o.reference_latency_s,
                     "[s] reference failure: each sample shows the attitude this long before its stamp")
          ->check(CLI::Range(0.0, 10.0));
  o.reference_bias_given =
      app.add_option(
             "--reference-bias", o.reference_bias,
             "ARCSEC,AT_S,RAMP_S: reference failure, a slow bias growing from AT_S to ARCSEC over RAMP_S")
          ->delimiter(',')
          ->expected(3);
  o.reference_misid_given =
      app.add_option("--reference-misid", o.reference_misid,
                     "DEG,AT_S,DURATION_S: reference failure, mis-identified (turned by DEG) for DURATION_S")
          ->delimiter(',')
          ->expected(3);
  o.acs_amplitude = app.add_option("--acs-amplitude", o.acs_amplitude_deg,
                                   "[deg] orbit/slews: attitude-control motion amplitude (0 = none)")
                        ->check(number_in(0.0, sim::kMaxAcsAmplitude_deg));
  o.acs_accel =
      app.add_option("--acs-accel", o.acs_accel_dps2, "[deg/s^2] orbit/slews: its peak acceleration")
          ->check(number_in(0.0, sim::kMaxAcsAccel_dps2, true));
  o.period =
      app.add_option("--orbit-period", o.orbit_period_min, "[min] orbit/slews: orbit period (one pitch turn)")
          ->check(number_in(sim::kMinOrbitPeriod_s / 60.0, sim::kMaxOrbitPeriod_s / 60.0));
  o.jitter = app.add_option("--jitter", o.jitter_s, "[s] sample-time jitter, uniform +-")
                 ->check(CLI::NonNegativeNumber);
  o.drop = app.add_option("--drop", o.drop_probability, "probability that a gyro sample is not delivered")
               ->check(CLI::Range(0.0, 1.0));
  o.range = app.add_option("--range", o.range_dps, "[deg/s] measuring range (saturation)")
                ->check(number_in(0.0, sim::kMaxRange_dps, true));
}

void add_turntable_options(CLI::App& app, SimArgs& a) {
  a.turntable_only = {
      app.add_option("--table-rate", a.plan.table_rate_dps, "[deg/s] turntable: gimbal rate")
          ->capture_default_str(),
      app.add_option("--revolutions", a.plan.revolutions, "turntable: revolutions per sequence")
          ->capture_default_str(),
      app.add_option("--order", a.plan.order,
                     "turntable: sequence numbers in the order run, e.g. 1,2,5,6 (default 1..16)")
          ->delimiter(','),
      app.add_flag("--wrap", a.plan.wrap_angles, "turntable: write encoder angles wrapped to (-180, 180]")};
}

bool looks_like_file(const std::string& scenario) {
  const auto ext = std::filesystem::path(scenario).extension().string();
  return ext == ".yaml" || ext == ".yml" || std::filesystem::exists(scenario);
}

bool is_turntable(const SimArgs& a) {
  return a.scenario_name == "turntable";
}

// The run's inputs recorded and its outputs opened (the turntable writes to standard output by default and
// has no truth file).
struct SimOutputs {
  OutputFile* log = nullptr;
  OutputFile* truth = nullptr;
};

Result<SimOutputs> open_files(SimArgs& a, RunFiles& files) {
  if (!a.unit_path.empty()) files.add_input(a.unit_path, "--unit");
  if (looks_like_file(a.scenario_name)) files.add_input(a.scenario_name, "SCENARIO");
  if (is_turntable(a) && a.out_path.empty()) a.out_path = "-";
  SimOutputs out;
  if (!a.out_path.empty()) {
    auto log = files.add(a.out_path, "--out");
    if (!log) return log.error();
    out.log = *log;
  }
  if (!a.truth_path.empty() && !is_turntable(a)) {
    auto truth = files.add(a.truth_path, "--truth");
    if (!truth) return truth.error();
    out.truth = *truth;
  }
  return out;
}

Result<std::optional<Calibration>> read_unit(const std::string& unit_path) {
  if (unit_path.empty()) return std::optional<Calibration>();
  auto read = read_calibration(unit_path);
  if (!read) return read.error();
  return std::optional<Calibration>(std::move(read.value()));
}

int run_turntable(const Calibration& unit, const sim::TurntablePlan& plan, const sim::GyroModelOptions& model,
                  std::uint64_t seed, RunFiles& files, OutputFile& out) {
  auto log = sim::simulate_turntable(unit, plan, seed, model);
  if (!log) return report(kSimName, log.error());
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  log->metadata.insert(log->metadata.end(), meta.begin(), meta.end());
  if (Status st = out.write(format_turntable_log(*log)); !st) return report(kSimName, st.error());
  if (Status st = files.commit(); !st) return report(kSimName, st.error());
  std::cerr << "tetra sim: turntable: " << log->rows() << " rows, " << unit.gyro_count() << " gyros"
            << (out.path() == "-" ? std::string() : " -> " + out.path()) << '\n';
  return kExitOk;
}

// The turntable scenario: only its options apply; the plan and the model with the options given.
int run_turntable_scenario(SimArgs& a, const std::optional<Calibration>& unit, RunFiles& files,
                           OutputFile& out) {
  const ScenarioOverrides& o = a.over;
  for (const CLI::Option* opt :
       {o.minutes_given, o.reference, o.reference_noise, o.reference_latency, o.reference_bias_given,
        o.reference_misid_given, o.acs_amplitude, o.acs_accel, o.period, o.jitter, o.drop}) {
    if (opt->count()) return report(kSimName, bad_input("turntable: " + opt->get_name() + " does not apply"));
  }
  if (!a.fault_texts.empty() || !a.add_fault_texts.empty() || !a.truth_path.empty()) {
    return report(kSimName, bad_input("turntable: --fault, --add-fault and --truth do not apply"));
  }
  if (o.rate->count()) a.plan.rate_hz = o.rate_hz;
  if (o.latitude->count()) a.plan.latitude_deg = o.latitude_deg;
  sim::GyroModelOptions model;
  if (o.range->count()) model.range_dps = o.range_dps;
  return run_turntable(unit ? *unit : seed_as_built_unit(), a.plan, model, a.seed, files, out);
}

void apply_overrides(const ScenarioOverrides& o, sim::Scenario& sc) {
  if (o.rate->count()) sc.rate_hz = o.rate_hz;
  if (o.minutes_given->count()) sc.duration_s = o.minutes * 60.0;
  if (o.latitude->count()) sc.motion.latitude_deg = o.latitude_deg;
  if (o.reference->count()) sc.reference.rate_hz = o.reference_hz;
  if (o.reference_noise->count()) sc.reference.noise_arcsec = o.reference_noise_arcsec;
  if (o.reference_latency->count()) sc.reference.latency_s = o.reference_latency_s;
  if (o.reference_bias.size() == 3) {
    sc.reference.bias_arcsec = o.reference_bias[0];
    sc.reference.bias_at_s = o.reference_bias[1];
    sc.reference.bias_ramp_s = o.reference_bias[2];
  }
  if (o.reference_misid.size() == 3) {
    sc.reference.misid_deg = o.reference_misid[0];
    sc.reference.misid_at_s = o.reference_misid[1];
    sc.reference.misid_duration_s = o.reference_misid[2];
  }
  if (o.acs_amplitude->count()) sc.motion.acs.amplitude_deg = o.acs_amplitude_deg;
  if (o.acs_accel->count()) sc.motion.acs.peak_accel_dps2 = o.acs_accel_dps2;
  if (o.period->count()) sc.motion.orbit_period_s = o.orbit_period_min * 60.0;
  if (o.jitter->count()) sc.jitter_s = o.jitter_s;
  if (o.drop->count()) sc.drop_probability = o.drop_probability;
  if (o.range->count()) sc.model.range_dps = o.range_dps;
}

// The options given that change the scenario, for a message: " (with --minutes, --rate-hz)".
std::string overrides_given(const ScenarioOverrides& o) {
  std::string names;
  for (const CLI::Option* opt : {o.rate, o.minutes_given, o.latitude, o.reference, o.reference_noise,
                                 o.acs_amplitude, o.acs_accel, o.period, o.jitter, o.drop, o.range}) {
    if (opt->count()) names += (names.empty() ? "" : ", ") + opt->get_name();
  }
  return names.empty() ? names : " (with " + names + ")";
}

// Any other scenario: built in or read from a file, then the unit and the options given.
Result<sim::Scenario> load_scenario(const SimArgs& a, const std::optional<Calibration>& unit) {
  for (const CLI::Option* opt : a.turntable_only) {
    if (opt->count()) return bad_input(opt->get_name() + " applies to the turntable scenario only");
  }
  Result<sim::Scenario> scenario = looks_like_file(a.scenario_name) ? sim::read_scenario(a.scenario_name)
                                                                    : sim::builtin_scenario(a.scenario_name);
  if (!scenario) return scenario.error();
  if (unit) scenario->unit = *unit;
  apply_overrides(a.over, *scenario);
  if (!a.fault_texts.empty()) scenario->faults.clear();  // the command line's faults replace the file's
  // Each option is in its own range; together (e.g. --minutes × --rate-hz) they may still not fit.
  if (Status st = sim::validate_scenario(*scenario); !st)
    return bad_input(st.error().message + overrides_given(a.over));
  return scenario;
}

Result<sim::SimOptions> sim_options(const SimArgs& a) {
  sim::SimOptions options;
  options.seed = a.seed;
  for (const auto* texts : {&a.fault_texts, &a.add_fault_texts}) {
    for (const std::string& text : *texts) {
      auto fault = sim::parse_fault_spec(text);
      if (!fault) return fault.error();
      options.faults.push_back(fault.value());
    }
  }
  if (a.loop.enabled && (!a.out_path.empty() || !a.truth_path.empty())) {
    return bad_input("--out and --truth do not apply with --closed-loop (see --pointing)");
  }
  return options;
}

// The open-loop run into the log (and truth) files.
int write_files(const SimArgs& a, const sim::Scenario& sc, const sim::SimOptions& options, RunFiles& files,
                const SimOutputs& out) {
  if (out.log == nullptr) return report(kSimName, bad_input("--out LOG.csv is required (or --dds)"));
  auto simulator = sim::Simulator::create(sc, options);
  if (!simulator) return report(kSimName, simulator.error());
  const bool long_run = simulator->epoch_count() > 2'000'000;
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status st =
          sim::write_simulation(*simulator, *out.log, out.truth, meta, long_run ? print_progress : nullptr);
      !st) {
    return report(kSimName, st.error());
  }
  if (Status st = files.commit(); !st) return report(kSimName, st.error());
  std::cerr << "tetra sim: " << sc.name << ": " << simulator->epoch_count() << " epochs, "
            << simulator->gyro_count() << " gyros -> " << a.out_path
            << (a.truth_path.empty() ? std::string() : ", truth -> " + a.truth_path) << '\n';
  return kExitOk;
}

// Closed loop (in process or over DDS), the open loop published over DDS, or the open loop to files.
int run_scenario(const SimArgs& a, const sim::Scenario& sc, const sim::SimOptions& options, RunFiles& files,
                 const SimOutputs& out) {
#if TETRA_WITH_DDS
  if (a.loop.enabled && a.dds.enabled) return sim_dds_closed_loop_main(sc, options, a.loop, a.dds);
#endif
  if (a.loop.enabled) return sim_closed_loop_main(sc, options, a.loop);
#if TETRA_WITH_DDS
  if (a.dds.enabled) {
    auto simulator = sim::Simulator::create(sc, options);
    if (!simulator) return report(kSimName, simulator.error());
    return sim_dds_main(*simulator, a.dds);
  }
#endif
  return write_files(a, sc, options, files, out);
}

// --write-unit FILE: the unit a run would simulate, as a calibration file (examples/seed_unit.yaml).
int write_unit(const SimArgs& a) {
  if (!a.scenario_name.empty()) return report(kSimName, bad_input("--write-unit takes no SCENARIO"));
  RunFiles files;
  if (!a.unit_path.empty()) files.add_input(a.unit_path, "--unit");
  auto out = files.add(a.write_unit_path, "--write-unit");
  if (!out) return report(kSimName, out.error());
  auto unit = read_unit(a.unit_path);
  if (!unit) return report(kSimName, unit.error());
  const Calibration cal = unit->has_value() ? **unit : seed_as_built_unit();
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status st = write_calibration(**out, cal, meta); !st) return report(kSimName, st.error());
  if (Status st = files.commit(); !st) return report(kSimName, st.error());
  std::cerr << "tetra sim: unit '" << cal.unit << "', " << cal.gyro_count() << " gyros -> "
            << a.write_unit_path << '\n';
  return kExitOk;
}

}  // namespace

int cmd_sim(int argc, char** argv) {
  CLI::App app{
      "Simulate a gyro unit with known truth. SCENARIO: turntable, static, lab-orbit, orbit, slews, or a "
      "scenario YAML file (docs/sim.md). Options given here override the scenario's (--fault replaces its "
      "faults, --add-fault adds to them).",
      kSimName};
  SimArgs a;
  add_run_options(app, a);
  add_scenario_options(app, a);
  add_turntable_options(app, a);
  add_closed_loop_options(app, a.loop);
#if TETRA_WITH_DDS
  add_sim_dds_options(app, a.dds);
#endif
  if (auto status = parse(app, argc, argv)) return *status;
  if (!a.write_unit_path.empty()) return write_unit(a);
  if (a.scenario_name.empty())
    return report(kSimName, bad_input("SCENARIO is required (or --write-unit FILE)"));

  RunFiles files;
  auto out = open_files(a, files);
  if (!out) return report(kSimName, out.error());
  auto unit = read_unit(a.unit_path);
  if (!unit) return report(kSimName, unit.error());
  if (is_turntable(a)) return run_turntable_scenario(a, *unit, files, *out->log);
  auto scenario = load_scenario(a, *unit);
  if (!scenario) return report(kSimName, scenario.error());
  auto options = sim_options(a);
  if (!options) return report(kSimName, options.error());
  return run_scenario(a, *scenario, *options, files, *out);
}

}  // namespace tetra::cli
