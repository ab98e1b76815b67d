// Simulated runs into files (tetra/report/sim_files.hpp).
#include "tetra/report/sim_files.hpp"

#include <filesystem>
#include <utility>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/sim/fault.hpp"

namespace tetra::report {

namespace {

bool is_scenario_file(const std::string& scenario) {
  const auto ext = std::filesystem::path(scenario).extension().string();
  return ext == ".yaml" || ext == ".yml" || std::filesystem::exists(scenario);
}

bool is_turntable(const SimRunOptions& o) {
  return o.scenario == "turntable";
}

// The run's inputs recorded and its outputs opened (the turntable writes to standard output by default and
// has no truth file).
struct SimOutputs {
  OutputFile* log = nullptr;
  OutputFile* truth = nullptr;
  std::string log_path;
};

Result<SimOutputs> open_sim_files(const SimRunOptions& o, RunFiles& files) {
  if (!o.unit_path.empty()) files.add_input(o.unit_path, name_of(o.names, "unit_path"));
  if (is_scenario_file(o.scenario)) files.add_input(o.scenario, name_of(o.names, "scenario"));
  SimOutputs out;
  out.log_path = is_turntable(o) && o.out_path.empty() ? "-" : o.out_path;
  if (!out.log_path.empty()) {
    auto log = files.add(out.log_path, name_of(o.names, "out_path"));
    if (!log) return log.error();
    out.log = *log;
  }
  if (!o.truth_path.empty() && !is_turntable(o)) {
    auto truth = files.add(o.truth_path, name_of(o.names, "truth_path"));
    if (!truth) return truth.error();
    out.truth = *truth;
  }
  return out;
}

Result<std::optional<Calibration>> read_sim_unit(const std::string& unit_path) {
  if (unit_path.empty()) return std::optional<Calibration>();
  auto read = read_calibration(unit_path);
  if (!read) return read.error();
  return std::optional<Calibration>(std::move(read.value()));
}

// The turntable scenario: only its options apply; the plan and the model with the options given.
Result<SimulatedFiles> simulate_turntable_file(const SimRunOptions& o, const std::optional<Calibration>& unit,
                                               RunFiles& files, OutputFile& out, std::ostream& err) {
  const ScenarioOverrides& v = o.overrides;
  const std::pair<bool, const char*> not_for_turntable[] = {
      {v.duration_min.has_value(), "duration_min"},
      {v.reference_hz.has_value(), "reference_hz"},
      {v.reference_noise_arcsec.has_value(), "reference_noise_arcsec"},
      {v.reference_latency_s.has_value(), "reference_latency_s"},
      {v.reference_bias.has_value(), "reference_bias"},
      {v.reference_misid.has_value(), "reference_misid"},
      {v.acs_amplitude_deg.has_value(), "acs_amplitude_deg"},
      {v.acs_accel_dps2.has_value(), "acs_accel_dps2"},
      {v.orbit_period_min.has_value(), "orbit_period_min"},
      {v.jitter_s.has_value(), "jitter_s"},
      {v.drop_probability.has_value(), "drop_probability"}};
  for (const auto& [given, argument] : not_for_turntable) {
    if (given) return bad_input("turntable: " + name_of(o.names, argument) + " does not apply");
  }
  if (!o.faults.empty() || !o.added_faults.empty() || !o.truth_path.empty()) {
    return bad_input("turntable: " + name_of(o.names, "faults") + ", " + name_of(o.names, "added_faults") +
                     " and " + name_of(o.names, "truth_path") + " do not apply");
  }
  sim::TurntablePlan plan = o.plan;
  if (v.rate_hz) plan.rate_hz = *v.rate_hz;
  if (v.latitude_deg) plan.latitude_deg = *v.latitude_deg;
  sim::GyroModelOptions model;
  if (v.range_dps) model.range_dps = *v.range_dps;
  const Calibration& cal = unit ? *unit : seed_as_built_unit();
  auto log = sim::simulate_turntable(cal, plan, o.seed, model);
  if (!log) return log.error();
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  log->metadata.insert(log->metadata.end(), meta.begin(), meta.end());
  if (Status st = out.write(format_turntable_log(*log)); !st) return st.error();
  if (Status st = files.commit(); !st) return st.error();
  err << name_of(o.names, "command") << ": turntable: " << log->rows() << " rows, " << cal.gyro_count()
      << " gyros" << (out.path() == "-" ? std::string() : " -> " + out.path()) << '\n';
  return SimulatedFiles{"turntable", log->rows(), cal.gyro_count()};
}

void apply_overrides(const ScenarioOverrides& o, sim::Scenario& sc) {
  if (o.rate_hz) sc.rate_hz = *o.rate_hz;
  if (o.duration_min) sc.duration_s = *o.duration_min * 60.0;
  if (o.latitude_deg) sc.motion.latitude_deg = *o.latitude_deg;
  if (o.reference_hz) sc.reference.rate_hz = *o.reference_hz;
  if (o.reference_noise_arcsec) sc.reference.noise_arcsec = *o.reference_noise_arcsec;
  if (o.reference_latency_s) sc.reference.latency_s = *o.reference_latency_s;
  if (o.reference_bias) {
    sc.reference.bias_arcsec = (*o.reference_bias)[0];
    sc.reference.bias_at_s = (*o.reference_bias)[1];
    sc.reference.bias_ramp_s = (*o.reference_bias)[2];
  }
  if (o.reference_misid) {
    sc.reference.misid_deg = (*o.reference_misid)[0];
    sc.reference.misid_at_s = (*o.reference_misid)[1];
    sc.reference.misid_duration_s = (*o.reference_misid)[2];
  }
  if (o.acs_amplitude_deg) sc.motion.acs.amplitude_deg = *o.acs_amplitude_deg;
  if (o.acs_accel_dps2) sc.motion.acs.peak_accel_dps2 = *o.acs_accel_dps2;
  if (o.orbit_period_min) sc.motion.orbit_period_s = *o.orbit_period_min * 60.0;
  if (o.jitter_s) sc.jitter_s = *o.jitter_s;
  if (o.drop_probability) sc.drop_probability = *o.drop_probability;
  if (o.range_dps) sc.model.range_dps = *o.range_dps;
}

// The overrides given that change the scenario, for a message: " (with --minutes, --rate-hz)".
std::string overrides_given(const SimRunOptions& run) {
  const ScenarioOverrides& o = run.overrides;
  const std::pair<bool, const char*> given[] = {
      {o.rate_hz.has_value(), "rate_hz"},
      {o.duration_min.has_value(), "duration_min"},
      {o.latitude_deg.has_value(), "latitude_deg"},
      {o.reference_hz.has_value(), "reference_hz"},
      {o.reference_noise_arcsec.has_value(), "reference_noise_arcsec"},
      {o.acs_amplitude_deg.has_value(), "acs_amplitude_deg"},
      {o.acs_accel_dps2.has_value(), "acs_accel_dps2"},
      {o.orbit_period_min.has_value(), "orbit_period_min"},
      {o.jitter_s.has_value(), "jitter_s"},
      {o.drop_probability.has_value(), "drop_probability"},
      {o.range_dps.has_value(), "range_dps"}};
  std::string names;
  for (const auto& [is_given, argument] : given) {
    if (is_given) names += (names.empty() ? "" : ", ") + name_of(run.names, argument);
  }
  return names.empty() ? names : " (with " + names + ")";
}

// Any other scenario: built in or read from a file, then the unit and the overrides.
Result<sim::Scenario> load_scenario(const SimRunOptions& o, const std::optional<Calibration>& unit) {
  if (!o.plan_given.empty())
    return bad_input(name_of(o.names, o.plan_given.front()) + " applies to the turntable scenario only");
  Result<sim::Scenario> scenario = is_scenario_file(o.scenario)
                                       ? sim::read_scenario(o.scenario, unit ? &*unit : nullptr)
                                       : sim::builtin_scenario(o.scenario);
  if (!scenario) return scenario.error();
  if (unit) scenario->unit = *unit;  // a built-in scenario's (a file took it before its checks)
  apply_overrides(o.overrides, *scenario);
  if (!o.faults.empty()) scenario->faults.clear();  // the run's faults replace the file's
  // Each override is in its own range; together (e.g. duration × rate) they may still not fit.
  if (Status st = sim::validate_scenario(*scenario); !st)
    return bad_input(st.error().message + overrides_given(o));
  return scenario;
}

Result<sim::SimOptions> simulator_options(const SimRunOptions& o) {
  sim::SimOptions options;
  options.seed = o.seed;
  for (const auto* texts : {&o.faults, &o.added_faults}) {
    for (const std::string& text : *texts) {
      auto fault = sim::parse_fault_spec(text);
      if (!fault) return fault.error();
      options.faults.push_back(fault.value());
    }
  }
  if (o.closed_loop && (!o.out_path.empty() || !o.truth_path.empty()))
    return bad_input(ErrorSubject(kSubjectClosedLoop), "out_path and truth_path do not apply");
  return options;
}

Result<PreparedSimulation> prepare_with_unit(const SimRunOptions& o, const std::optional<Calibration>& unit) {
  auto scenario = load_scenario(o, unit);
  if (!scenario) return scenario.error();
  auto options = simulator_options(o);
  if (!options) return options.error();
  return PreparedSimulation{std::move(scenario).value(), std::move(options).value()};
}

}  // namespace

Result<PreparedSimulation> prepare_simulation(const SimRunOptions& o) {
  auto unit = read_sim_unit(o.unit_path);
  if (!unit) return unit.error();
  return prepare_with_unit(o, *unit);
}

Result<SimulatedFiles> simulate_to_files(const SimRunOptions& o, std::ostream& err) {
  RunFiles files;
  auto out = open_sim_files(o, files);
  if (!out) return out.error();
  auto unit = read_sim_unit(o.unit_path);
  if (!unit) return unit.error();
  if (is_turntable(o)) return simulate_turntable_file(o, *unit, files, *out->log, err);
  auto prepared = prepare_with_unit(o, *unit);
  if (!prepared) return prepared.error();
  if (out->log == nullptr) return bad_input(ErrorSubject(kSubjectMissingOut), "out_path is required");
  auto simulator = sim::Simulator::create(prepared->scenario, prepared->options);
  if (!simulator) return simulator.error();
  const bool long_run = simulator->epoch_count() > 2'000'000;
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status st =
          sim::write_simulation(*simulator, *out->log, out->truth, meta, long_run ? o.progress : nullptr);
      !st)
    return st.error();
  if (Status st = files.commit(); !st) return st.error();
  err << name_of(o.names, "command") << ": " << prepared->scenario.name << ": " << simulator->epoch_count()
      << " epochs, " << simulator->gyro_count() << " gyros -> " << o.out_path
      << (o.truth_path.empty() ? std::string() : ", truth -> " + o.truth_path) << '\n';
  return SimulatedFiles{prepared->scenario.name, simulator->epoch_count(), simulator->gyro_count()};
}

Result<Calibration> write_simulated_unit(const std::string& unit_path, const std::string& out_path,
                                         const ArgumentNames& names, std::ostream& err) {
  RunFiles files;
  if (!unit_path.empty()) files.add_input(unit_path, name_of(names, "unit_path"));
  auto out = files.add(out_path, name_of(names, "out_path"));
  if (!out) return out.error();
  auto unit = read_sim_unit(unit_path);
  if (!unit) return unit.error();
  Calibration cal = unit->has_value() ? **unit : seed_as_built_unit();
  const auto meta = provenance_metadata(provenance(files.input_paths()));
  if (Status st = write_calibration(**out, cal, meta); !st) return st.error();
  if (Status st = files.commit(); !st) return st.error();
  err << name_of(names, "command") << ": unit '" << cal.unit << "', " << cal.gyro_count() << " gyros -> "
      << out_path << '\n';
  return cal;
}

}  // namespace tetra::report
