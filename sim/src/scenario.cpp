#include "tetra/sim/scenario.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "tetra/core/csv.hpp"

namespace tetra::sim {

namespace {

constexpr double kMaxEpochs = 2.0e9;  // a guard against absurd durations × rates

std::string number_text(double value) {
  std::string out;
  append_double(out, value);
  return out;
}

// --- YAML helpers. Exceptions never leave this file: parse_scenario turns them into an Error. ---

struct ParseError {
  std::string message;
};

struct Ctx {
  const std::string& source;
  std::string at(const YAML::Node& node) const {
    const auto mark = node.Mark();
    if (mark.line < 0) return source + ": ";
    return source + ":" + std::to_string(mark.line + 1) + ": ";
  }
};

void check_keys(const Ctx& ctx, const YAML::Node& map, const std::set<std::string>& allowed,
                const std::string& what) {
  if (!map.IsMap()) throw ParseError{ctx.at(map) + what + ": expected a mapping"};
  for (const auto& kv : map) {
    const auto key = kv.first.as<std::string>();
    if (allowed.count(key) == 0) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw ParseError{ctx.at(kv.first) + what + "unknown key '" + key + "' (allowed: " + list + ")"};
    }
  }
}

double number(const Ctx& ctx, const YAML::Node& node, const std::string& what) {
  try {
    const double v = node.as<double>();
    if (!std::isfinite(v)) throw ParseError{ctx.at(node) + what + ": must be finite"};
    return v;
  } catch (const YAML::Exception&) {
    throw ParseError{ctx.at(node) + what + ": '" + (node.IsScalar() ? node.Scalar() : std::string("?")) +
                     "' is not a number"};
  }
}

void maybe_number(const Ctx& ctx, const YAML::Node& parent, const std::string& key, const std::string& prefix,
                  double& out) {
  const YAML::Node node = parent[key];
  if (node) out = number(ctx, node, prefix + key);
}

Eigen::Vector3d vector3(const Ctx& ctx, const YAML::Node& node, const std::string& what) {
  if (!node.IsSequence() || node.size() != 3) throw ParseError{ctx.at(node) + what + ": expected [x, y, z]"};
  Eigen::Vector3d v;
  for (std::size_t i = 0; i < 3; ++i) {
    v[static_cast<Eigen::Index>(i)] = number(ctx, node[i], what + "[" + std::to_string(i) + "]");
  }
  return v;
}

Eigen::Vector3d axis_from(const Ctx& ctx, const YAML::Node& node, const std::string& what) {
  if (node.IsScalar()) {
    const std::string& name = node.Scalar();
    if (name == "x" || name == "+x") return Eigen::Vector3d::UnitX();
    if (name == "y" || name == "+y") return Eigen::Vector3d::UnitY();
    if (name == "z" || name == "+z") return Eigen::Vector3d::UnitZ();
    if (name == "-x") return -Eigen::Vector3d::UnitX();
    if (name == "-y") return -Eigen::Vector3d::UnitY();
    if (name == "-z") return -Eigen::Vector3d::UnitZ();
    throw ParseError{ctx.at(node) + what + ": '" + name + "' is not an axis (x, y, z, -x, ... or [x, y, z])"};
  }
  const Eigen::Vector3d v = vector3(ctx, node, what);
  if (v.norm() < 1e-9) throw ParseError{ctx.at(node) + what + ": must not be the zero vector"};
  return v.normalized();
}

Scenario parse_yaml(const YAML::Node& root, const Ctx& ctx, const std::string& base_dir) {
  check_keys(ctx, root,
             {"scenario", "duration_s", "rate_hz", "latitude_deg", "pitch_rate_dps", "orbit_period_s", "acs",
              "slews", "reference", "unit", "gyro_model", "jitter_s", "drop_probability", "faults"},
             "");
  const YAML::Node base = root["scenario"];
  if (!base) throw ParseError{ctx.at(root) + "missing key 'scenario' (static, lab-orbit, orbit or slews)"};
  auto builtin = builtin_scenario(base.as<std::string>());
  if (!builtin) throw ParseError{ctx.at(base) + "scenario: " + builtin.error().message};
  Scenario sc = builtin.value();
  sc.name = ctx.source;
  maybe_number(ctx, root, "duration_s", "", sc.duration_s);
  maybe_number(ctx, root, "rate_hz", "", sc.rate_hz);
  maybe_number(ctx, root, "latitude_deg", "", sc.motion.latitude_deg);
  maybe_number(ctx, root, "pitch_rate_dps", "", sc.motion.pitch_rate_dps);
  maybe_number(ctx, root, "orbit_period_s", "", sc.motion.orbit_period_s);
  maybe_number(ctx, root, "jitter_s", "", sc.jitter_s);
  maybe_number(ctx, root, "drop_probability", "", sc.drop_probability);
  if (const YAML::Node acs = root["acs"]) {
    check_keys(ctx, acs, {"amplitude_deg", "peak_accel_dps2"}, "acs: ");
    maybe_number(ctx, acs, "amplitude_deg", "acs.", sc.motion.acs.amplitude_deg);
    maybe_number(ctx, acs, "peak_accel_dps2", "acs.", sc.motion.acs.peak_accel_dps2);
  }
  if (const YAML::Node slews = root["slews"]) {
    if (!slews.IsSequence()) throw ParseError{ctx.at(slews) + "slews: expected a list"};
    if (sc.motion.kind != MotionKind::kSlews) {
      throw ParseError{ctx.at(slews) + "slews: only the 'slews' scenario has slews"};
    }
    sc.motion.slews.clear();
    for (std::size_t i = 0; i < slews.size(); ++i) {
      const YAML::Node s = slews[i];
      const std::string what = "slews[" + std::to_string(i) + "].";
      check_keys(ctx, s, {"axis", "angle_deg", "start_s", "duration_s"}, what + " ");
      Slew slew;
      for (const char* key : {"axis", "angle_deg", "start_s", "duration_s"}) {
        if (!s[key]) throw ParseError{ctx.at(s) + what + key + ": missing"};
      }
      slew.axis_B = axis_from(ctx, s["axis"], what + "axis");
      slew.angle_deg = number(ctx, s["angle_deg"], what + "angle_deg");
      slew.start_s = number(ctx, s["start_s"], what + "start_s");
      slew.duration_s = number(ctx, s["duration_s"], what + "duration_s");
      if (slew.duration_s <= 0.0)
        throw ParseError{ctx.at(s["duration_s"]) + what + "duration_s: must be positive"};
      sc.motion.slews.push_back(slew);
    }
  }
  if (const YAML::Node ref = root["reference"]) {
    check_keys(ctx, ref, {"rate_hz", "noise_arcsec"}, "reference: ");
    maybe_number(ctx, ref, "rate_hz", "reference.", sc.reference.rate_hz);
    maybe_number(ctx, ref, "noise_arcsec", "reference.", sc.reference.noise_arcsec);
  }
  if (const YAML::Node model = root["gyro_model"]) {
    check_keys(ctx, model, {"bias_instability_correlation_s", "range_dps"}, "gyro_model: ");
    maybe_number(ctx, model, "bias_instability_correlation_s", "gyro_model.",
                 sc.model.bias_instability_correlation_s);
    if (const YAML::Node range = model["range_dps"]; range && !range.IsNull()) {
      sc.model.range_dps = number(ctx, range, "gyro_model.range_dps");
    }
  }
  if (const YAML::Node unit = root["unit"]) {
    std::filesystem::path path = unit.as<std::string>();
    if (path.is_relative()) path = std::filesystem::path(base_dir) / path;
    auto cal = read_calibration(path.string());
    if (!cal) throw ParseError{ctx.at(unit) + "unit: " + cal.error().message};
    sc.unit = std::move(cal.value());
  }
  if (const YAML::Node faults = root["faults"]) {
    if (!faults.IsSequence()) throw ParseError{ctx.at(faults) + "faults: expected a list of fault specs"};
    for (std::size_t i = 0; i < faults.size(); ++i) {
      auto fault = parse_fault_spec(faults[i].as<std::string>());
      if (!fault)
        throw ParseError{ctx.at(faults[i]) + "faults[" + std::to_string(i) + "]: " + fault.error().message};
      sc.faults.push_back(fault.value());
    }
  }
  // Range checks with the line of the key where it exists.
  if (Status st = validate_scenario(sc); !st) throw ParseError{ctx.at(root) + st.error().message};
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
                                const std::string& base_dir) {
  const Ctx ctx{source};
  try {
    const YAML::Node root = YAML::Load(yaml_text);
    if (!root || root.IsNull()) return bad_input(source + ": empty scenario file");
    return parse_yaml(root, ctx, base_dir);
  } catch (const ParseError& e) {
    return bad_input(e.message);
  } catch (const YAML::Exception& e) {
    const int line = e.mark.line < 0 ? 0 : e.mark.line + 1;
    return bad_input(source + ":" + std::to_string(line) + ": " + e.msg);
  }
}

Result<Scenario> read_scenario(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return bad_input(path + ": cannot open scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parse_scenario(text.str(), path, parent.empty() ? "." : parent.string());
}

Status validate_scenario(const Scenario& sc) {
  if (Status st = validate_calibration(sc.unit, "unit"); !st) return st;
  if (!std::isfinite(sc.duration_s) || sc.duration_s <= 0.0) {
    return bad_input("duration_s must be positive, got " + number_text(sc.duration_s));
  }
  if (!std::isfinite(sc.rate_hz) || sc.rate_hz <= 0.0) {
    return bad_input("rate_hz must be positive, got " + number_text(sc.rate_hz));
  }
  if (sc.duration_s * sc.rate_hz < 1.0 || sc.duration_s * sc.rate_hz > kMaxEpochs) {
    return bad_input("duration_s × rate_hz = " + number_text(sc.duration_s * sc.rate_hz) +
                     " epochs; need at least 1 and at most 2e9");
  }
  if (!std::isfinite(sc.jitter_s) || sc.jitter_s < 0.0 || sc.jitter_s >= 0.5 / sc.rate_hz) {
    return bad_input("jitter_s must be in [0, half the sampling period), got " + number_text(sc.jitter_s));
  }
  if (!std::isfinite(sc.drop_probability) || sc.drop_probability < 0.0 || sc.drop_probability > 1.0) {
    return bad_input("drop_probability must be in [0, 1], got " + number_text(sc.drop_probability));
  }
  if (!std::isfinite(sc.reference.rate_hz) || sc.reference.rate_hz < 0.0 ||
      sc.reference.rate_hz > sc.rate_hz) {
    return bad_input("reference rate_hz must be in [0, rate_hz], got " + number_text(sc.reference.rate_hz));
  }
  if (!std::isfinite(sc.reference.noise_arcsec) || sc.reference.noise_arcsec < 0.0) {
    return bad_input("reference noise_arcsec must not be negative, got " +
                     number_text(sc.reference.noise_arcsec));
  }
  if (!std::isfinite(sc.model.bias_instability_correlation_s) ||
      sc.model.bias_instability_correlation_s <= 0.0) {
    return bad_input("gyro_model bias_instability_correlation_s must be positive");
  }
  if (sc.model.range_dps && (!std::isfinite(*sc.model.range_dps) || *sc.model.range_dps <= 0.0)) {
    return bad_input("gyro_model range_dps must be positive");
  }
  for (const FaultSpec& f : sc.faults) {
    if (f.gyro < 1 || f.gyro > sc.unit.gyro_count()) {
      return bad_input("fault '" + format_fault_spec(f) + "': gyro " + std::to_string(f.gyro) +
                       " does not exist (the unit has " + std::to_string(sc.unit.gyro_count()) + " gyros)");
    }
    if (f.kind == FaultKind::kNoise) {
      const auto& noise = sc.unit.gyros[static_cast<std::size_t>(f.gyro - 1)].noise;
      if (!noise || !noise->arw_dps_rtHz || *noise->arw_dps_rtHz == 0.0) {
        return bad_input("fault '" + format_fault_spec(f) + "': gyro " + std::to_string(f.gyro) +
                         " has no white noise (noise: arw_dps_rtHz) for a noise fault to multiply");
      }
    }
  }
  return ok_status();
}

}  // namespace tetra::sim
