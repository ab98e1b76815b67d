// tetra sim SCENARIO — simulated gyro data with known truth (see docs/sim.md; tetra/report/sim_files.hpp).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iostream>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "sim_closed_loop.hpp"
#include "tetra/report/sim_files.hpp"
#include "tetra/sim/simulator.hpp"
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

int report_sim(const Error& error) {
  return report(
      kSimName, error,
      {{report::kSubjectMissingOut, "--out LOG.csv is required (or --dds)"},
       {report::kSubjectClosedLoop, "--out and --truth do not apply with --closed-loop (see --pointing)"}});
}

// The options given, as the report library's run options; messages name each by its option.
report::SimRunOptions run_options(const SimArgs& a) {
  report::SimRunOptions r;
  r.scenario = a.scenario_name;
  r.seed = a.seed;
  r.unit_path = a.unit_path;
  r.out_path = a.out_path;
  r.truth_path = a.truth_path;
  r.faults = a.fault_texts;
  r.added_faults = a.add_fault_texts;
  r.names = {{"command", "tetra sim"},       {"unit_path", "--unit"},   {"scenario", "SCENARIO"},
             {"out_path", "--out"},          {"truth_path", "--truth"}, {"faults", "--fault"},
             {"added_faults", "--add-fault"}};
  const ScenarioOverrides& o = a.over;
  report::ScenarioOverrides& v = r.overrides;
  const std::tuple<const CLI::Option*, std::optional<double>*, double, const char*> values[] = {
      {o.rate, &v.rate_hz, o.rate_hz, "rate_hz"},
      {o.minutes_given, &v.duration_min, o.minutes, "duration_min"},
      {o.latitude, &v.latitude_deg, o.latitude_deg, "latitude_deg"},
      {o.reference, &v.reference_hz, o.reference_hz, "reference_hz"},
      {o.reference_noise, &v.reference_noise_arcsec, o.reference_noise_arcsec, "reference_noise_arcsec"},
      {o.reference_latency, &v.reference_latency_s, o.reference_latency_s, "reference_latency_s"},
      {o.acs_amplitude, &v.acs_amplitude_deg, o.acs_amplitude_deg, "acs_amplitude_deg"},
      {o.acs_accel, &v.acs_accel_dps2, o.acs_accel_dps2, "acs_accel_dps2"},
      {o.period, &v.orbit_period_min, o.orbit_period_min, "orbit_period_min"},
      {o.jitter, &v.jitter_s, o.jitter_s, "jitter_s"},
      {o.drop, &v.drop_probability, o.drop_probability, "drop_probability"},
      {o.range, &v.range_dps, o.range_dps, "range_dps"}};
  for (const auto& [option, value, given, argument] : values) {
    if (option->count()) *value = given;
    r.names[argument] = option->get_name();
  }
  if (o.reference_bias.size() == 3)
    v.reference_bias = {o.reference_bias[0], o.reference_bias[1], o.reference_bias[2]};
  if (o.reference_misid.size() == 3)
    v.reference_misid = {o.reference_misid[0], o.reference_misid[1], o.reference_misid[2]};
  r.names["reference_bias"] = o.reference_bias_given->get_name();
  r.names["reference_misid"] = o.reference_misid_given->get_name();
  r.plan = a.plan;
  const char* plan_arguments[] = {"table_rate_dps", "revolutions", "order", "wrap_angles"};
  for (std::size_t k = 0; k < a.turntable_only.size(); ++k) {
    if (a.turntable_only[k]->count()) r.plan_given.emplace_back(plan_arguments[k]);
    r.names[plan_arguments[k]] = a.turntable_only[k]->get_name();
  }
  r.closed_loop = a.loop.enabled;
  r.progress = print_progress;
  return r;
}

// Closed loop (in process or over DDS) or the open loop published over DDS, on the scenario prepared.
int run_elsewhere(const SimArgs& a, const report::SimRunOptions& run) {
  auto prepared = report::prepare_simulation(run);
  if (!prepared) return report_sim(prepared.error());
#if TETRA_WITH_DDS
  if (a.loop.enabled && a.dds.enabled)
    return sim_dds_closed_loop_main(prepared->scenario, prepared->options, a.loop, a.dds);
#endif
  if (a.loop.enabled) return sim_closed_loop_main(prepared->scenario, prepared->options, a.loop);
#if TETRA_WITH_DDS
  auto simulator = sim::Simulator::create(prepared->scenario, prepared->options);
  if (!simulator) return report(kSimName, simulator.error());
  return sim_dds_main(*simulator, a.dds);
#else
  return kExitFailure;
#endif
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
  if (!a.write_unit_path.empty()) {
    if (!a.scenario_name.empty()) return report(kSimName, bad_input("--write-unit takes no SCENARIO"));
    auto unit = report::write_simulated_unit(
        a.unit_path, a.write_unit_path,
        {{"command", "tetra sim"}, {"unit_path", "--unit"}, {"out_path", "--write-unit"}}, std::cerr);
    return unit ? kExitOk : report(kSimName, unit.error());
  }
  if (a.scenario_name.empty())
    return report(kSimName, bad_input("SCENARIO is required (or --write-unit FILE)"));
  const report::SimRunOptions run = run_options(a);
#if TETRA_WITH_DDS
  const bool dds = a.dds.enabled;
#else
  const bool dds = false;
#endif
  if ((a.loop.enabled || dds) && run.scenario != "turntable") return run_elsewhere(a, run);
  if (auto files = report::simulate_to_files(run, std::cerr); !files) return report_sim(files.error());
  return kExitOk;
}

}  // namespace tetra::cli
