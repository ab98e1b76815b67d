#include "tetra/sim/scenario.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "ranges.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/yaml_reader.hpp"
#include "text.hpp"
#include "yaml_fields.hpp"

namespace tetra::sim {

namespace {

Result<Slew> parse_slew(const YamlReader& yaml, const YAML::Node& s, const std::string& what) {
  if (Status st = yaml.check_keys(s, {"axis", "angle_deg", "start_s", "duration_s"}, what); !st)
    return st.error();
  for (const char* key : {"axis", "angle_deg", "start_s", "duration_s"}) {
    if (!s[key]) return yaml.error(s, what + "." + key, "missing");
  }
  Slew slew;
  const auto axis = axis_from(yaml, s["axis"], what + ".axis");
  if (!axis) return axis.error();
  slew.axis_B = *axis;
  if (Status st = maybe_numbers(
          yaml, s, what,
          {{"angle_deg", &slew.angle_deg}, {"start_s", &slew.start_s}, {"duration_s", &slew.duration_s}});
      !st)
    return st.error();
  if (slew.duration_s <= 0.0) return yaml.error(s["duration_s"], what + ".duration_s", "must be positive");
  return slew;
}

// The built-in scenario named by key 'scenario', after the file's keys are checked.
Result<Scenario> base_scenario(const YAML::Node& root, const YamlReader& yaml) {
  if (Status st = yaml.check_keys(root,
                                  {"scenario", "duration_s", "rate_hz", "latitude_deg", "pitch_rate_dps",
                                   "orbit_period_s", "acs", "slews", "reference", "unit", "gyro_model",
                                   "thermal", "jitter_s", "drop_probability", "faults", "closed_loop"},
                                  "");
      !st)
    return st.error();
  const YAML::Node base = root["scenario"];
  if (!base) return yaml.error(root, "", "missing key 'scenario' (static, lab-orbit, orbit or slews)");
  auto base_name = yaml.text(base, "scenario");
  if (!base_name) return base_name.error();
  auto builtin = builtin_scenario(*base_name);
  if (!builtin) return yaml.error(base, "scenario", builtin.error().message);
  Scenario sc = builtin.value();
  sc.name = yaml.source();
  return sc;
}

Status read_top_numbers(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  return maybe_numbers(yaml, root, "",
                       {{"duration_s", &sc.duration_s},
                        {"rate_hz", &sc.rate_hz},
                        {"latitude_deg", &sc.motion.latitude_deg},
                        {"pitch_rate_dps", &sc.motion.pitch_rate_dps},
                        {"orbit_period_s", &sc.motion.orbit_period_s},
                        {"jitter_s", &sc.jitter_s},
                        {"drop_probability", &sc.drop_probability}});
}

Status read_acs(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  const YAML::Node acs = root["acs"];
  if (!acs) return ok_status();
  if (Status st = yaml.check_keys(acs, {"amplitude_deg", "peak_accel_dps2"}, "acs"); !st) return st;
  return maybe_numbers(
      yaml, acs, "acs",
      {{"amplitude_deg", &sc.motion.acs.amplitude_deg}, {"peak_accel_dps2", &sc.motion.acs.peak_accel_dps2}});
}

Status read_slews(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  const YAML::Node slews = root["slews"];
  if (!slews) return ok_status();
  if (!slews.IsSequence()) return yaml.error(slews, "slews", "expected a list");
  if (sc.motion.kind != MotionKind::kSlews)
    return yaml.error(slews, "slews", "only the 'slews' scenario has slews");
  sc.motion.slews.clear();
  for (std::size_t i = 0; i < slews.size(); ++i) {
    auto slew = parse_slew(yaml, slews[i], "slews[" + std::to_string(i) + "]");
    if (!slew) return slew.error();
    sc.motion.slews.push_back(*slew);
  }
  return ok_status();
}

Status read_reference(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  const YAML::Node ref = root["reference"];
  if (!ref) return ok_status();
  ReferenceOptions& r = sc.reference;
  if (Status st =
          yaml.check_keys(ref,
                          {"rate_hz", "noise_arcsec", "latency_s", "bias_arcsec", "bias_at_s", "bias_ramp_s",
                           "misid_deg", "misid_at_s", "misid_duration_s", "drop_probability"},
                          "reference");
      !st)
    return st;
  return maybe_numbers(yaml, ref, "reference",
                       {{"rate_hz", &r.rate_hz},
                        {"noise_arcsec", &r.noise_arcsec},
                        {"latency_s", &r.latency_s},
                        {"bias_arcsec", &r.bias_arcsec},
                        {"bias_at_s", &r.bias_at_s},
                        {"bias_ramp_s", &r.bias_ramp_s},
                        {"misid_deg", &r.misid_deg},
                        {"misid_at_s", &r.misid_at_s},
                        {"misid_duration_s", &r.misid_duration_s},
                        {"drop_probability", &r.drop_probability}});
}

Status read_gyro_model(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  const YAML::Node model = root["gyro_model"];
  if (!model) return ok_status();
  if (Status st = yaml.check_keys(model, {"bias_instability_correlation_s", "range_dps"}, "gyro_model"); !st)
    return st;
  if (Status st = maybe_number(yaml, model, "bias_instability_correlation_s", "gyro_model",
                               sc.model.bias_instability_correlation_s);
      !st)
    return st;
  const auto range = yaml.optional_number(model, "range_dps", "gyro_model");
  if (!range) return range.error();
  if (*range) sc.model.range_dps = **range;
  return ok_status();
}

// The warm-up: the temperature transient and one bias coefficient per gyro (checked against the unit in
// validate_scenario).
Status read_thermal(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  const YAML::Node thermal = root["thermal"];
  if (!thermal) return ok_status();
  ThermalOptions& t = sc.thermal;
  if (Status st = yaml.check_keys(
          thermal, {"start_C", "end_C", "time_constant_s", "calibrated_at_C", "bias_dps_per_K"}, "thermal");
      !st)
    return st;
  if (Status st = maybe_numbers(yaml, thermal, "thermal",
                                {{"start_C", &t.start_C},
                                 {"end_C", &t.end_C},
                                 {"time_constant_s", &t.time_constant_s},
                                 {"calibrated_at_C", &t.calibrated_at_C}});
      !st)
    return st;
  const YAML::Node c = thermal["bias_dps_per_K"];
  if (!c) return yaml.error(thermal, "thermal.bias_dps_per_K", "missing (one coefficient per gyro)");
  if (!c.IsSequence() || c.size() == 0)
    return yaml.error(c, "thermal.bias_dps_per_K", "expected a list of numbers, one per gyro");
  t.bias_dps_per_K.clear();
  for (std::size_t i = 0; i < c.size(); ++i) {
    auto v = yaml.number(c[i], "thermal.bias_dps_per_K[" + std::to_string(i) + "]");
    if (!v) return v.error();
    t.bias_dps_per_K.push_back(*v);
  }
  return ok_status();
}

// The unit's calibration file, relative to the scenario file's folder `base_dir`.
Status read_unit(const YamlReader& yaml, const YAML::Node& root, const std::string& base_dir, Scenario& sc) {
  const YAML::Node unit = root["unit"];
  if (!unit) return ok_status();
  auto unit_path = yaml.text(unit, "unit");
  if (!unit_path) return unit_path.error();
  std::filesystem::path path = *unit_path;
  if (path.is_relative()) path = std::filesystem::path(base_dir) / path;
  auto cal = read_calibration(path.string());
  if (!cal) return yaml.error(unit, "unit", cal.error().message);
  sc.unit = std::move(cal.value());
  sc.named_files.push_back(path.string());
  return ok_status();
}

Status read_faults(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  const YAML::Node faults = root["faults"];
  if (!faults) return ok_status();
  if (!faults.IsSequence()) return yaml.error(faults, "faults", "expected a list of fault specs");
  for (std::size_t i = 0; i < faults.size(); ++i) {
    auto spec = yaml.text(faults[i], "faults[" + std::to_string(i) + "]");
    if (!spec) return spec.error();
    auto fault = parse_fault_spec(*spec);
    if (!fault) return yaml.error(faults[i], "faults[" + std::to_string(i) + "]", fault.error().message);
    sc.faults.push_back(fault.value());
  }
  return ok_status();
}

Status read_closed_loop(const YamlReader& yaml, const YAML::Node& root, Scenario& sc) {
  const YAML::Node loop = root["closed_loop"];
  if (!loop) return ok_status();
  if (sc.motion.kind != MotionKind::kOrbit)
    return yaml.error(loop, "closed_loop", "needs 'scenario: orbit' (the orbit the spacecraft flies)");
  auto spec = parse_closed_loop(yaml, loop);
  if (!spec) return spec.error();
  sc.closed_loop = std::move(spec.value());
  return ok_status();
}

// The built-in scenario, then each section of the file over it, in this order; then the ranges.
Result<Scenario> parse_yaml(const YAML::Node& root, const YamlReader& yaml, const std::string& base_dir,
                            const Calibration* unit) {
  auto sc = base_scenario(root, yaml);
  if (!sc) return sc.error();
  for (auto* read_section :
       {read_top_numbers, read_acs, read_slews, read_reference, read_gyro_model, read_thermal}) {
    if (Status st = read_section(yaml, root, *sc); !st) return st.error();
  }
  if (Status st = read_unit(yaml, root, base_dir, *sc); !st) return st.error();
  if (unit != nullptr) sc->unit = *unit;
  for (auto* read_section : {read_faults, read_closed_loop}) {
    if (Status st = read_section(yaml, root, *sc); !st) return st.error();
  }
  // Range checks with the line of the key where it exists.
  if (Status st = validate_scenario(*sc); !st)
    return yaml.error(node_named(root, st.error().message), "", st.error().message);
  return sc;
}

}  // namespace

std::vector<std::string> builtin_scenario_names() {
  return {"static", "lab-orbit", "orbit", "slews"};
}

Result<Scenario> builtin_scenario(const std::string& name) {
  Scenario sc;
  sc.name = name;
  if (name == "static") {
    // The seed's Allan test: 2 h at rest in the lab.
    sc.motion.kind = MotionKind::kStatic;
    sc.duration_s = 7200.0;
    sc.rate_hz = 10.0;
    sc.motion.acs.amplitude_deg = 0.0;
  } else if (name == "lab-orbit") {
    // The seed's attitude experiment: 0.06 deg/s about body Y for 100 min, every 0.8 s.
    sc.motion.kind = MotionKind::kLabOrbit;
    sc.duration_s = 6000.0;
    sc.rate_hz = 1.25;
    sc.motion.pitch_rate_dps = 0.06;
    sc.motion.acs.amplitude_deg = 0.0;
  } else if (name == "orbit" || name == "slews") {
    sc.motion.kind = name == "orbit" ? MotionKind::kOrbit : MotionKind::kSlews;
    sc.duration_s = 6000.0;
    sc.rate_hz = 10.0;
    sc.motion.orbit_period_s = 6000.0;
    sc.reference.rate_hz = 1.0;
    sc.reference.noise_arcsec = 5.0;
    if (name == "slews") {
      sc.motion.slews = {{Eigen::Vector3d::UnitX(), 30.0, 1200.0, 120.0},
                         {Eigen::Vector3d::UnitX(), -30.0, 2400.0, 120.0},
                         {Eigen::Vector3d::UnitZ(), 45.0, 3600.0, 150.0},
                         {Eigen::Vector3d::UnitZ(), -45.0, 4800.0, 150.0}};
    }
  } else {
    return bad_input("unknown scenario '" + name +
                     "' (built-in: turntable, static, lab-orbit, orbit, slews; or a .yaml file)");
  }
  return sc;
}

Result<Scenario> parse_scenario(const std::string& yaml_text, const std::string& source,
                                const std::string& base_dir, const Calibration* unit) {
  const YamlReader yaml{source};
  try {
    auto loaded = yaml.load(yaml_text);
    if (!loaded) return loaded.error();
    const YAML::Node root = *loaded;
    if (!root || root.IsNull()) return bad_input(source + ": empty scenario file");
    return parse_yaml(root, yaml, base_dir, unit);
  } catch (const YAML::Exception& e) {
    return yaml.error(e, "");
  }
}

Result<Scenario> read_scenario(const std::string& path, const Calibration* unit) {
  auto text = read_input(path, kMaxYamlBytes);
  if (!text) return text.error();
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parse_scenario(*text, path, parent.empty() ? "." : parent.string(), unit);
}

namespace {

Status validate_thermal(const ThermalOptions& t, int gyro_count) {
  if (!t.active()) return ok_status();
  for (const auto& [value, key] : {std::pair{t.start_C, "thermal.start_C"}, {t.end_C, "thermal.end_C"}}) {
    if (Status st = check_range(key, value, kMinTemperature_C, kMaxTemperature_C, "degC"); !st) return st;
  }
  if (!std::isnan(t.calibrated_at_C)) {
    if (Status st = check_range("thermal.calibrated_at_C", t.calibrated_at_C, kMinTemperature_C,
                                kMaxTemperature_C, "degC");
        !st)
      return st;
  }
  if (Status st = check_range("thermal.time_constant_s", t.time_constant_s, 0.0, kMaxDuration_s, "s", true);
      !st)
    return st;
  if (static_cast<int>(t.bias_dps_per_K.size()) != gyro_count) {
    return bad_input("thermal.bias_dps_per_K has " + std::to_string(t.bias_dps_per_K.size()) +
                     " coefficients; the unit has " + std::to_string(gyro_count) + " gyros (one each)");
  }
  const double cal_C = std::isnan(t.calibrated_at_C) ? t.end_C : t.calibrated_at_C;
  const double kelvin = std::max(std::abs(t.start_C - cal_C), std::abs(t.end_C - cal_C));
  for (const double c : t.bias_dps_per_K) {
    if (!std::isfinite(c) || std::abs(c) * kelvin > kMaxThermalBias_dps) {
      return bad_input("thermal.bias_dps_per_K: " + number_text(c) + " deg/s/K over " + number_text(kelvin) +
                       " K is a bias above " + number_text(kMaxThermalBias_dps) + " deg/s");
    }
  }
  return ok_status();
}

}  // namespace

Status validate_scenario(const Scenario& sc) {
  if (Status st = validate_calibration(sc.unit, "unit"); !st) return st;
  if (Status st = check_range("duration_s", sc.duration_s, 0.0, kMaxDuration_s, "s", true); !st) return st;
  if (Status st = check_range("rate_hz", sc.rate_hz, 0.0, kMaxRate_hz, "Hz", true); !st) return st;
  if (sc.duration_s * sc.rate_hz < 1.0 || sc.duration_s * sc.rate_hz > kMaxEpochs) {
    return bad_input("duration_s × rate_hz = " + number_text(sc.duration_s * sc.rate_hz) +
                     " epochs; need at least 1 and at most 2e9");
  }
  if (Status st = validate_motion(sc.motion); !st) return st;
  if (!std::isfinite(sc.jitter_s) || sc.jitter_s < 0.0 || sc.jitter_s >= 0.5 / sc.rate_hz) {
    return bad_input("jitter_s must be in [0, half the sampling period), got " + number_text(sc.jitter_s));
  }
  if (Status st = check_range("drop_probability", sc.drop_probability, 0.0, 1.0, ""); !st) return st;
  if (Status st = check_range("reference.rate_hz", sc.reference.rate_hz, 0.0, sc.rate_hz, "Hz"); !st)
    return st;
  if (Status st = check_range("reference.noise_arcsec", sc.reference.noise_arcsec, 0.0,
                              kMaxReferenceNoise_arcsec, "arcsec");
      !st)
    return st;
  const ReferenceOptions& r = sc.reference;
  if (!std::isfinite(r.latency_s) || r.latency_s < 0.0 || r.latency_s > 10.0)
    return bad_input("reference latency_s must be in [0, 10], got " + number_text(r.latency_s));
  if (!(r.drop_probability >= 0.0 && r.drop_probability < 1.0))
    return bad_input("reference drop_probability must be in [0, 1), got " + number_text(r.drop_probability));
  for (const auto& [value, key] : {std::pair{r.bias_arcsec, "bias_arcsec"},
                                   {r.bias_at_s, "bias_at_s"},
                                   {r.misid_deg, "misid_deg"},
                                   {r.misid_at_s, "misid_at_s"}}) {
    if (!std::isfinite(value)) return bad_input(std::string("reference ") + key + " must be finite");
  }
  for (const auto& [value, key] :
       {std::pair{r.bias_ramp_s, "bias_ramp_s"}, {r.misid_duration_s, "misid_duration_s"}}) {
    if (!std::isfinite(value) || value < 0.0)
      return bad_input(std::string("reference ") + key + " must not be negative, got " + number_text(value));
  }
  if (Status st = check_range("gyro_model.bias_instability_correlation_s",
                              sc.model.bias_instability_correlation_s, 0.0, kMaxCorrelation_s, "s", true);
      !st)
    return st;
  if (sc.model.range_dps) {
    if (Status st =
            check_range("gyro_model.range_dps", *sc.model.range_dps, 0.0, kMaxRange_dps, "deg/s", true);
        !st)
      return st;
  }
  if (Status st = validate_thermal(sc.thermal, sc.unit.gyro_count()); !st) return st;
  for (const FaultSpec& f : sc.faults) {
    if (f.gyro < 1 || f.gyro > sc.unit.gyro_count()) {
      return bad_input("fault '" + format_fault_spec(f) + "': gyro " + std::to_string(f.gyro) +
                       " does not exist (the unit has " + std::to_string(sc.unit.gyro_count()) + " gyros)");
    }
    if (f.at_s >= sc.duration_s) {
      return bad_input("fault '" + format_fault_spec(f) + "': starts at " + number_text(f.at_s) +
                       " s, at or after the end of the run (" + number_text(sc.duration_s) + " s)");
    }
    if (f.kind == FaultKind::kNoise) {
      const auto& noise = sc.unit.gyros[static_cast<std::size_t>(f.gyro - 1)].noise;
      if (!noise || !noise->arw_dps_rtHz || *noise->arw_dps_rtHz == 0.0) {
        return bad_input("fault '" + format_fault_spec(f) + "': gyro " + std::to_string(f.gyro) +
                         " has no white noise (noise: arw_dps_rtHz) for a noise fault to multiply");
      }
    }
  }
  if (sc.closed_loop) {
    if (Status st = validate_closed_loop(*sc.closed_loop); !st)
      return bad_input("closed_loop: " + st.error().message);
    if (sc.jitter_s != 0.0) return bad_input("closed_loop: jitter_s does not apply in closed loop");
  }
  return ok_status();
}

}  // namespace tetra::sim
