#include "tetra/core/calibration_file.hpp"

#include <cmath>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "tetra/core/csv.hpp"

namespace tetra {

Eigen::MatrixX3d Calibration::axes_B() const {
  Eigen::MatrixX3d h(gyros.size(), 3);
  for (std::size_t i = 0; i < gyros.size(); ++i)
    h.row(static_cast<Eigen::Index>(i)) = gyros[i].axis_B.transpose();
  return h;
}

Calibration seed_as_built_unit() {
  Calibration cal;
  cal.unit = "seed-as-built";
  cal.latitude_deg = -23.2;
  cal.method = "seed-tables-4-5";
  const double s[4] = {0.0730, 0.0785, 0.0880, 0.0775};
  const double b[4] = {0.0002, 0.0004, 0.0002, -0.0003};
  const double h[4][3] = {{0.55526, -0.00146, 0.83167},
                          {0.42638, 0.78516, -0.44914},
                          {0.51389, -0.74179, -0.43088},
                          {0.99999, -0.00094, 0.00065}};
  for (int i = 0; i < 4; ++i) {
    GyroCalibration g;
    g.id = i + 1;
    g.scale_factor_V_per_dps = s[i];
    g.bias_V = b[i];
    g.axis_B = Eigen::Vector3d(h[i][0], h[i][1], h[i][2]).normalized();
    GyroNoise n;
    n.arw_dps_rtHz = 3.0e-5;
    n.bias_instability_dps = 5.0e-6;
    g.noise = n;
    cal.gyros.push_back(g);
  }
  return cal;
}

namespace {

struct Ctx {
  const std::string& source;
  std::string at(const YAML::Node& node) const {
    const auto mark = node.Mark();
    if (mark.line < 0) return source + ": ";
    return source + ":" + std::to_string(mark.line + 1) + ": ";
  }
};

// Exceptions never leave this file: parse_calibration catches them and returns an Error.
struct ParseError {
  std::string message;
};

void check_keys(const Ctx& ctx, const YAML::Node& map, const std::set<std::string>& allowed,
                const std::string& what) {
  if (!map.IsMap()) throw ParseError{ctx.at(map) + what + ": expected a mapping"};
  for (const auto& kv : map) {
    const auto key = kv.first.as<std::string>();
    if (allowed.count(key) == 0) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw ParseError{ctx.at(kv.first) + what + ": unknown key '" + key + "' (allowed: " + list + ")"};
    }
  }
}

double number(const Ctx& ctx, const YAML::Node& parent, const std::string& key, const std::string& what) {
  const YAML::Node node = parent[key];
  if (!node) throw ParseError{ctx.at(parent) + what + ": missing key '" + key + "'"};
  try {
    const double v = node.as<double>();
    if (!std::isfinite(v)) throw ParseError{ctx.at(node) + what + "." + key + ": must be finite"};
    return v;
  } catch (const YAML::Exception&) {
    throw ParseError{ctx.at(node) + what + "." + key + ": '" + (node.IsScalar() ? node.Scalar() : "?") +
                     "' is not a number"};
  }
}

std::optional<double> optional_number(const Ctx& ctx, const YAML::Node& parent, const std::string& key,
                                      const std::string& what) {
  const YAML::Node node = parent[key];
  if (!node || node.IsNull()) return std::nullopt;
  return number(ctx, parent, key, what);
}

Eigen::Vector3d vector3(const Ctx& ctx, const YAML::Node& parent, const std::string& key,
                        const std::string& what) {
  const YAML::Node node = parent[key];
  if (!node) throw ParseError{ctx.at(parent) + what + ": missing key '" + key + "'"};
  if (!node.IsSequence() || node.size() != 3)
    throw ParseError{ctx.at(node) + what + "." + key + ": expected [x, y, z]"};
  Eigen::Vector3d v;
  for (std::size_t i = 0; i < 3; ++i) {
    try {
      v[static_cast<Eigen::Index>(i)] = node[i].as<double>();
    } catch (const YAML::Exception&) {
      throw ParseError{ctx.at(node[i]) + what + "." + key + "[" + std::to_string(i) + "]: not a number"};
    }
    if (!std::isfinite(v[static_cast<Eigen::Index>(i)])) {
      throw ParseError{ctx.at(node[i]) + what + "." + key + ": must be finite"};
    }
  }
  return v;
}

GyroCalibration parse_gyro(const Ctx& ctx, const YAML::Node& g, std::size_t index) {
  const std::string what = "gyros[" + std::to_string(index) + "]";
  check_keys(ctx, g, {"id", "scale_factor_V_per_dps", "bias_V", "axis", "sigma", "noise"}, what);
  GyroCalibration out;
  const double id = number(ctx, g, "id", what);
  if (id != std::floor(id) || id < 1 || id > 64)
    throw ParseError{ctx.at(g["id"]) + what + ".id: must be 1..N"};
  out.id = static_cast<int>(id);
  out.scale_factor_V_per_dps = number(ctx, g, "scale_factor_V_per_dps", what);
  if (out.scale_factor_V_per_dps == 0.0) {
    throw ParseError{ctx.at(g["scale_factor_V_per_dps"]) + what +
                     ".scale_factor_V_per_dps: must not be zero"};
  }
  out.bias_V = number(ctx, g, "bias_V", what);
  const Eigen::Vector3d axis = vector3(ctx, g, "axis", what);
  const double norm = axis.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    std::ostringstream msg;
    msg << ctx.at(g["axis"]) << what << ".axis: norm " << norm << " is not 1 (a unit vector is required)";
    throw ParseError{msg.str()};
  }
  // Normalize five-decimal table values; leave full-precision unit vectors bit-exact.
  out.axis_B = std::abs(norm - 1.0) > 1e-12 ? Eigen::Vector3d(axis / norm) : axis;
  if (const YAML::Node s = g["sigma"]; s && !s.IsNull()) {
    const std::string sw = what + ".sigma";
    check_keys(ctx, s, {"scale_factor_V_per_dps", "bias_V", "axis"}, sw);
    GyroSigma sigma;
    sigma.scale_factor_V_per_dps = optional_number(ctx, s, "scale_factor_V_per_dps", sw).value_or(0.0);
    sigma.bias_V = optional_number(ctx, s, "bias_V", sw).value_or(0.0);
    if (s["axis"]) sigma.axis = vector3(ctx, s, "axis", sw);
    out.sigma = sigma;
  }
  if (const YAML::Node n = g["noise"]; n && !n.IsNull()) {
    const std::string nw = what + ".noise";
    check_keys(ctx, n,
               {"quantization_deg", "arw_dps_rtHz", "bias_instability_dps", "rate_random_walk_dps_per_rts",
                "rate_ramp_dps_per_s"},
               nw);
    GyroNoise noise;
    noise.quantization_deg = optional_number(ctx, n, "quantization_deg", nw);
    noise.arw_dps_rtHz = optional_number(ctx, n, "arw_dps_rtHz", nw);
    noise.bias_instability_dps = optional_number(ctx, n, "bias_instability_dps", nw);
    noise.rate_random_walk_dps_per_rts = optional_number(ctx, n, "rate_random_walk_dps_per_rts", nw);
    noise.rate_ramp_dps_per_s = optional_number(ctx, n, "rate_ramp_dps_per_s", nw);
    for (const auto& v : {noise.quantization_deg, noise.arw_dps_rtHz, noise.bias_instability_dps,
                          noise.rate_random_walk_dps_per_rts, noise.rate_ramp_dps_per_s}) {
      if (v && *v < 0.0) throw ParseError{ctx.at(n) + nw + ": noise terms must not be negative"};
    }
    out.noise = noise;
  }
  return out;
}

}  // namespace

Result<Calibration> parse_calibration(const std::string& yaml_text, const std::string& source) {
  const Ctx ctx{source};
  try {
    const YAML::Node root = YAML::Load(yaml_text);
    if (!root || root.IsNull()) return bad_input(source + ": empty calibration file");
    check_keys(ctx, root, {"unit", "latitude_deg", "method", "gyros"}, "calibration");
    Calibration cal;
    cal.unit = root["unit"] ? root["unit"].as<std::string>() : "";
    cal.latitude_deg = optional_number(ctx, root, "latitude_deg", "calibration");
    cal.method = root["method"] ? root["method"].as<std::string>() : "";
    const YAML::Node gyros = root["gyros"];
    if (!gyros) return bad_input(source + ": missing key 'gyros'");
    if (!gyros.IsSequence()) return bad_input(ctx.at(gyros) + "gyros: expected a list");
    for (std::size_t i = 0; i < gyros.size(); ++i) cal.gyros.push_back(parse_gyro(ctx, gyros[i], i));
    const Status valid = validate_calibration(cal, source);
    if (!valid) return valid.error();
    return cal;
  } catch (const ParseError& e) {
    return bad_input(e.message);
  } catch (const YAML::Exception& e) {
    return bad_input(source + ":" + std::to_string(e.mark.line + 1) + ": YAML: " + e.msg);
  }
}

Result<Calibration> read_calibration(const std::string& path) {
  auto text = read_text_file(path);
  if (!text) return text.error();
  return parse_calibration(*text, path);
}

Status validate_calibration(const Calibration& cal, const std::string& source) {
  if (cal.gyros.size() < 3) {
    return bad_input(source + ": " + std::to_string(cal.gyros.size()) +
                     " gyros listed, at least 3 are needed");
  }
  for (std::size_t i = 0; i < cal.gyros.size(); ++i) {
    const auto& g = cal.gyros[i];
    if (g.id != static_cast<int>(i + 1)) {
      return bad_input(source + ": gyros[" + std::to_string(i) + "].id is " + std::to_string(g.id) +
                       ", expected " + std::to_string(i + 1) + " (ids 1..N in order)");
    }
    if (!std::isfinite(g.scale_factor_V_per_dps) || g.scale_factor_V_per_dps == 0.0 ||
        !std::isfinite(g.bias_V)) {
      return bad_input(source + ": gyro " + std::to_string(g.id) +
                       ": scale factor and bias must be finite, scale non-zero");
    }
    if (std::abs(g.axis_B.norm() - 1.0) > 1e-9) {
      return bad_input(source + ": gyro " + std::to_string(g.id) + ": axis is not a unit vector");
    }
  }
  return ok_status();
}

namespace {

std::string num(double v) {
  std::string s;
  append_double(s, v);
  return s;
}

std::string vec(const Eigen::Vector3d& v) {
  return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]";
}

}  // namespace

std::string format_calibration(const Calibration& cal) {
  std::string out;
  out += "# tetra calibration: y_i = (g_i - bias_V) / scale_factor_V_per_dps = axis . omega_B [deg/s]\n";
  out += "unit: \"" + cal.unit + "\"\n";
  if (cal.latitude_deg) out += "latitude_deg: " + num(*cal.latitude_deg) + "\n";
  if (!cal.method.empty()) out += "method: " + cal.method + "\n";
  out += "gyros:\n";
  for (const auto& g : cal.gyros) {
    out += "  - id: " + std::to_string(g.id) + "\n";
    out += "    scale_factor_V_per_dps: " + num(g.scale_factor_V_per_dps) + "\n";
    out += "    bias_V: " + num(g.bias_V) + "\n";
    out += "    axis: " + vec(g.axis_B) + "\n";
    if (g.sigma) {
      out += "    sigma:\n";
      out += "      scale_factor_V_per_dps: " + num(g.sigma->scale_factor_V_per_dps) + "\n";
      out += "      bias_V: " + num(g.sigma->bias_V) + "\n";
      out += "      axis: " + vec(g.sigma->axis) + "\n";
    }
    if (g.noise) {
      out += "    noise:\n";
      const auto put = [&out](const char* key, const std::optional<double>& v) {
        if (v) out += std::string("      ") + key + ": " + num(*v) + "\n";
      };
      put("quantization_deg", g.noise->quantization_deg);
      put("arw_dps_rtHz", g.noise->arw_dps_rtHz);
      put("bias_instability_dps", g.noise->bias_instability_dps);
      put("rate_random_walk_dps_per_rts", g.noise->rate_random_walk_dps_per_rts);
      put("rate_ramp_dps_per_s", g.noise->rate_ramp_dps_per_s);
    }
  }
  return out;
}

Status write_calibration(const std::string& path, const Calibration& cal) {
  return write_text_file(path, format_calibration(cal));
}

}  // namespace tetra
