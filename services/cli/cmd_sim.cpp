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

void print_sim_progress(double fraction) {
  std::cerr << "tetra sim: " << std::lround(fraction * 100.0) << " %\n";
}

struct SimArgs {
  report::SimRunOptions run;            // bound to the options; names filled as they are added
  std::string write_unit_path;          // --write-unit: the simulated unit as a calibration YAML, then stop
  std::vector<double> reference_bias;   // arcsec, at s, ramp s
  std::vector<double> reference_misid;  // deg, at s, duration s
  std::vector<CLI::Option*> turntable_only;  // --table-rate, --revolutions, --order, --wrap
  ClosedLoopCliOptions loop;
#if TETRA_WITH_DDS
  SimDdsCliOptions dds;
#endif
};

// `option`, its name recorded as the messages' name of the library's `argument`.
CLI::Option* named(SimArgs& a, CLI::Option* option, const char* argument) {
  a.run.names[argument] = option->get_name();
  return option;
}

void add_run_options(CLI::App& app, SimArgs& a) {
  app.add_option("SCENARIO", a.run.scenario, "turntable | static | lab-orbit | orbit | slews | FILE.yaml");
  app.add_option("--write-unit", a.write_unit_path,
                 "write the simulated unit (the seed paper's as-built unit, or --unit's) as a calibration "
                 "YAML to FILE and stop (no SCENARIO)");
  app.add_option("--seed", a.run.seed, "random seed; the same seed gives byte-identical output")
      ->capture_default_str();
  app.add_option("--unit", a.run.unit_path,
                 "calibration YAML of the simulated unit (the as-built truth, with its noise: sections); "
                 "default: the seed paper's unit");
  app.add_option(
      "--out,-o", a.run.out_path,
      "output log: CSV, or HDF5 when named .h5 (- = standard output, CSV only; turntable: CSV, the default)");
  app.add_option("--truth", a.run.truth_path, "truth file: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps");
}

void add_scenario_options(CLI::App& app, SimArgs& a) {
  report::ScenarioOverrides& o = a.run.overrides;
  // The ranges are the scenario keys' (docs/sim.md, "Ranges"), checked here to name the option.
  named(a, app.add_option("--rate-hz", o.rate_hz, "[Hz] gyro sampling rate"), "rate_hz")
      ->check(number_in(0.0, sim::kMaxRate_hz, true));
  named(a, app.add_option("--minutes", o.duration_min, "[min] duration (not for turntable)"), "duration_min")
      ->check(number_in(0.0, sim::kMaxDuration_s / 60.0, true));
  named(
      a,
      app.add_option("--latitude", o.latitude_deg, "[deg] geodetic latitude (turntable, static, lab-orbit)"),
      "latitude_deg")
      ->check(CLI::Range(-90.0, 90.0));
  named(
      a,
      app.add_option("--fault", a.run.faults,
                     "gyro=N,kind=K,at=S[,size=X][,until=S] (repeatable; docs/interfaces.md §2.7); replaces "
                     "the scenario file's faults"),
      "faults");
  named(a,
        app.add_option(
            "--add-fault", a.run.added_faults,
            "a fault added to the scenario file's faults (and to --fault's), same syntax; repeatable"),
        "added_faults");
  named(a, app.add_option("--reference-hz", o.reference_hz, "[Hz] attitude reference rate (0 = none)"),
        "reference_hz")
      ->check(CLI::NonNegativeNumber);
  named(a,
        app.add_option("--reference-noise", o.reference_noise_arcsec, "[arcsec] reference 1-sigma per axis"),
        "reference_noise_arcsec")
      ->check(number_in(0.0, sim::kMaxReferenceNoise_arcsec));
  named(a,
        app.add_option("--reference-latency", o.reference_latency_s,
                       "[s] reference failure: each sample shows the attitude this long before its stamp"),
        "reference_latency_s")
      ->check(CLI::Range(0.0, 10.0));
  named(a,
        app.add_option(
            "--reference-bias", a.reference_bias,
            "ARCSEC,AT_S,RAMP_S: reference failure, a slow bias growing from AT_S to ARCSEC over RAMP_S"),
        "reference_bias")
      ->delimiter(',')
      ->expected(3);
  named(
      a,
      app.add_option("--reference-misid", a.reference_misid,
                     "DEG,AT_S,DURATION_S: reference failure, mis-identified (turned by DEG) for DURATION_S"),
      "reference_misid")
      ->delimiter(',')
      ->expected(3);
  named(a,
        app.add_option("--acs-amplitude", o.acs_amplitude_deg,
                       "[deg] orbit/slews: attitude-control motion amplitude (0 = none)"),
        "acs_amplitude_deg")
      ->check(number_in(0.0, sim::kMaxAcsAmplitude_deg));
  named(a, app.add_option("--acs-accel", o.acs_accel_dps2, "[deg/s^2] orbit/slews: its peak acceleration"),
        "acs_accel_dps2")
      ->check(number_in(0.0, sim::kMaxAcsAccel_dps2, true));
  named(a,
        app.add_option("--orbit-period", o.orbit_period_min,
                       "[min] orbit/slews: orbit period (one pitch turn)"),
        "orbit_period_min")
      ->check(number_in(sim::kMinOrbitPeriod_s / 60.0, sim::kMaxOrbitPeriod_s / 60.0));
  named(a, app.add_option("--jitter", o.jitter_s, "[s] sample-time jitter, uniform +-"), "jitter_s")
      ->check(CLI::NonNegativeNumber);
  named(a, app.add_option("--drop", o.drop_probability, "probability that a gyro sample is not delivered"),
        "drop_probability")
      ->check(CLI::Range(0.0, 1.0));
  named(a, app.add_option("--range", o.range_dps, "[deg/s] measuring range (saturation)"), "range_dps")
      ->check(number_in(0.0, sim::kMaxRange_dps, true));
}

void add_turntable_options(CLI::App& app, SimArgs& a) {
  sim::TurntablePlan& plan = a.run.plan;
  a.turntable_only = {
      named(a, app.add_option("--table-rate", plan.table_rate_dps, "[deg/s] turntable: gimbal rate"),
            "table_rate_dps")
          ->capture_default_str(),
      named(a, app.add_option("--revolutions", plan.revolutions, "turntable: revolutions per sequence"),
            "revolutions")
          ->capture_default_str(),
      named(a,
            app.add_option("--order", plan.order,
                           "turntable: sequence numbers in the order run, e.g. 1,2,5,6 (default 1..16)"),
            "order")
          ->delimiter(','),
      named(
          a,
          app.add_flag("--wrap", plan.wrap_angles, "turntable: write encoder angles wrapped to (-180, 180]"),
          "wrap_angles")};
}

int report_sim(const Error& error) {
  return report(
      kSimName, error,
      {{report::kSubjectMissingOut, "--out LOG.csv is required (or --dds)"},
       {report::kSubjectClosedLoop, "--out and --truth do not apply with --closed-loop (see --pointing)"}});
}

// The rest of the run's options: the reference failures, the turntable options given, the closed loop.
void complete_run_options(SimArgs& a) {
  report::SimRunOptions& r = a.run;
  if (a.reference_bias.size() == 3)
    r.overrides.reference_bias = {a.reference_bias[0], a.reference_bias[1], a.reference_bias[2]};
  if (a.reference_misid.size() == 3)
    r.overrides.reference_misid = {a.reference_misid[0], a.reference_misid[1], a.reference_misid[2]};
  const char* plan_arguments[] = {"table_rate_dps", "revolutions", "order", "wrap_angles"};
  for (std::size_t k = 0; k < a.turntable_only.size(); ++k) {
    if (a.turntable_only[k]->count()) r.plan_given.emplace_back(plan_arguments[k]);
  }
  r.closed_loop = a.loop.enabled;
  r.progress = print_sim_progress;
  r.names.insert({{"command", "tetra sim"},
                  {"unit_path", "--unit"},
                  {"scenario", "SCENARIO"},
                  {"out_path", "--out"},
                  {"truth_path", "--truth"}});
}

// Closed loop (in process or over DDS) or the open loop published over DDS, on the scenario prepared.
int run_elsewhere(const SimArgs& a, const report::SimRunOptions& run) {
  auto prepared = report::prepare_simulation(run);
  if (!prepared) return report_sim(prepared.error());
#if TETRA_WITH_DDS
  if (a.loop.enabled && a.dds.enabled)
    return sim_dds_closed_loop_main(prepared->scenario, prepared->options, a.loop, a.dds);
#endif
  if (a.loop.enabled) {
    const Status st =
        report::run_closed_loop_to_files(prepared->scenario, prepared->options, a.loop, std::cout);
    return st ? kExitOk : report(kSimName, st.error());
  }
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
    if (!a.run.scenario.empty()) return report(kSimName, bad_input("--write-unit takes no SCENARIO"));
    auto unit = report::write_simulated_unit(
        a.run.unit_path, a.write_unit_path,
        {{"command", "tetra sim"}, {"unit_path", "--unit"}, {"out_path", "--write-unit"}}, std::cerr);
    return unit ? kExitOk : report(kSimName, unit.error());
  }
  if (a.run.scenario.empty())
    return report(kSimName, bad_input("SCENARIO is required (or --write-unit FILE)"));
  complete_run_options(a);
  const report::SimRunOptions& run = a.run;
#if TETRA_WITH_DDS
  const bool dds = a.dds.enabled;
#else
  const bool dds = false;
#endif
  // The open loop over DDS writes no files: refused rather than ignored. The same scenario and seed without
  // --dds writes the same epochs and truth (docs/dds.md, "tetra sim SCENARIO --dds").
  if (dds && !a.loop.enabled && run.scenario != "turntable" &&
      (!run.out_path.empty() || !run.truth_path.empty()))
    return report(kSimName, bad_input("--out and --truth do not apply with --dds: run the same scenario and "
                                      "--seed without --dds to write the log and the truth"));
  if ((a.loop.enabled || dds) && run.scenario != "turntable") return run_elsewhere(a, run);
  if (auto files = report::simulate_to_files(run, std::cerr); !files) return report_sim(files.error());
  return kExitOk;
}

}  // namespace tetra::cli
