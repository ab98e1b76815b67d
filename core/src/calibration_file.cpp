#include "tetra/core/calibration_file.hpp"

#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/yaml_reader.hpp"

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

//! A scale factor the conversion y = (g − bias) / scale keeps finite and meaningful: a normal number
//! (no denormal such as 1e-320, whose reciprocal overflows) of magnitude within the stated bounds.
bool plausible_scale_factor(double scale_V_per_dps) {
  const double magnitude = std::abs(scale_V_per_dps);
  return std::isfinite(magnitude) && magnitude >= kMinScaleFactor_V_per_dps &&
         magnitude <= kMaxScaleFactor_V_per_dps;
}

const char* const kScaleFactorRange = "must be a number with magnitude in [1e-9, 1e9] V/(deg/s), not zero";

Result<GyroCalibration> parse_gyro(const YamlReader& yaml, const YAML::Node& g, std::size_t index) {
  const std::string what = "gyros[" + std::to_string(index) + "]";
  if (Status st =
          yaml.check_keys(g, {"id", "scale_factor_V_per_dps", "bias_V", "axis", "sigma", "noise"}, what);
      !st)
    return st.error();
  GyroCalibration out;
  const auto id = yaml.required_number(g, "id", what);
  if (!id) return id.error();
  if (*id != std::floor(*id) || *id < 1 || *id > 64) return yaml.error(g["id"], what + ".id", "must be 1..N");
  out.id = static_cast<int>(*id);
  const auto scale = yaml.required_number(g, "scale_factor_V_per_dps", what);
  if (!scale) return scale.error();
  if (!plausible_scale_factor(*scale))
    return yaml.error(g["scale_factor_V_per_dps"], what + ".scale_factor_V_per_dps", kScaleFactorRange);
  out.scale_factor_V_per_dps = *scale;
  const auto bias = yaml.required_number(g, "bias_V", what);
  if (!bias) return bias.error();
  out.bias_V = *bias;
  const auto axis = yaml.required_vector3(g, "axis", what);
  if (!axis) return axis.error();
  const double norm = axis->norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    std::ostringstream msg;
    msg << "norm " << norm << " is not 1 (a unit vector is required)";
    return yaml.error(g["axis"], what + ".axis", msg.str());
  }
  // Normalize five-decimal table values; leave full-precision unit vectors bit-exact.
  out.axis_B = std::abs(norm - 1.0) > 1e-12 ? Eigen::Vector3d(*axis / norm) : *axis;
  if (const YAML::Node s = g["sigma"]; s && !s.IsNull()) {
    const std::string sw = what + ".sigma";
    if (Status st = yaml.check_keys(s, {"scale_factor_V_per_dps", "bias_V", "axis"}, sw); !st)
      return st.error();
    GyroSigma sigma;
    const auto sigma_scale = yaml.optional_number(s, "scale_factor_V_per_dps", sw);
    if (!sigma_scale) return sigma_scale.error();
    const auto sigma_bias = yaml.optional_number(s, "bias_V", sw);
    if (!sigma_bias) return sigma_bias.error();
    sigma.scale_factor_V_per_dps = sigma_scale->value_or(0.0);
    sigma.bias_V = sigma_bias->value_or(0.0);
    if (s["axis"]) {
      const auto sigma_axis = yaml.required_vector3(s, "axis", sw);
      if (!sigma_axis) return sigma_axis.error();
      sigma.axis = *sigma_axis;
    }
    for (const char* key : {"scale_factor_V_per_dps", "bias_V", "axis"}) {
      const double smallest = std::string(key) == "axis"     ? sigma.axis.minCoeff()
                              : std::string(key) == "bias_V" ? sigma.bias_V
                                                             : sigma.scale_factor_V_per_dps;
      if (smallest < 0.0) return yaml.error(s[key], sw + "." + key, "a 1-sigma must not be negative");
    }
    out.sigma = sigma;
  }
  if (const YAML::Node n = g["noise"]; n && !n.IsNull()) {
    const std::string nw = what + ".noise";
    GyroNoise noise;
    const std::pair<const char*, std::optional<double>*> terms[] = {
        {"quantization_deg", &noise.quantization_deg},
        {"arw_dps_rtHz", &noise.arw_dps_rtHz},
        {"bias_instability_dps", &noise.bias_instability_dps},
        {"rate_random_walk_dps_per_rts", &noise.rate_random_walk_dps_per_rts},
        {"rate_ramp_dps_per_s", &noise.rate_ramp_dps_per_s},
    };
    std::vector<std::string> allowed;
    for (const auto& [key, field] : terms) allowed.emplace_back(key);
    if (Status st = yaml.check_keys(n, allowed, nw); !st) return st.error();
    for (const auto& [key, field] : terms) {
      auto v = yaml.optional_number(n, key, nw);
      if (!v) return v.error();
      *field = *v;
    }
    for (const auto& [key, field] : terms) {
      if (*field && **field < 0.0) return yaml.error(n[key], nw + "." + key, "must not be negative");
    }
    out.noise = noise;
  }
  return out;
}

}  // namespace

Result<Calibration> parse_calibration(const std::string& yaml_text, const std::string& source) {
  const YamlReader yaml{source};
  try {
    auto loaded = yaml.load(yaml_text);
    if (!loaded) return loaded.error();
    const YAML::Node root = *loaded;
    if (!root || root.IsNull()) return bad_input(source + ": empty calibration file");
    if (Status st = yaml.check_keys(root, {"unit", "latitude_deg", "method", "gyros"}, "calibration"); !st)
      return st.error();
    Calibration cal;
    auto unit = yaml.optional_text(root, "unit", "");
    if (!unit) return unit.error();
    cal.unit = *unit;
    const auto latitude = yaml.optional_number(root, "latitude_deg", "");
    if (!latitude) return latitude.error();
    if (*latitude && std::abs(**latitude) > 90.0)
      return yaml.error(root["latitude_deg"], "latitude_deg", "must be within [-90, 90] deg");
    cal.latitude_deg = *latitude;
    auto method = yaml.optional_text(root, "method", "");
    if (!method) return method.error();
    cal.method = *method;
    const YAML::Node gyros = root["gyros"];
    if (!gyros) return bad_input(source + ": missing key 'gyros'");
    if (!gyros.IsSequence()) return yaml.error(gyros, "gyros", "expected a list");
    for (std::size_t i = 0; i < gyros.size(); ++i) {
      auto gyro = parse_gyro(yaml, gyros[i], i);
      if (!gyro) return gyro.error();
      cal.gyros.push_back(std::move(*gyro));
    }
    const Status valid = validate_calibration(cal, source);
    if (!valid) return valid.error();
    return cal;
  } catch (const YAML::Exception& e) {
    return yaml.error(e, "YAML");
  }
}

Result<Calibration> read_calibration(const std::string& path) {
  auto text = read_input(path, kMaxYamlBytes);
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
    if (!plausible_scale_factor(g.scale_factor_V_per_dps) || !std::isfinite(g.bias_V)) {
      return bad_input(source + ": gyro " + std::to_string(g.id) + ": bias must be finite, scale factor " +
                       kScaleFactorRange);
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

void emit_vector(YAML::Emitter& out, const Eigen::Vector3d& v) {
  out << YAML::Flow << YAML::BeginSeq << num(v.x()) << num(v.y()) << num(v.z()) << YAML::EndSeq;
}

void emit_gyro(YAML::Emitter& out, const GyroCalibration& g) {
  out << YAML::BeginMap;
  out << YAML::Key << "id" << YAML::Value << g.id;
  out << YAML::Key << "scale_factor_V_per_dps" << YAML::Value << num(g.scale_factor_V_per_dps);
  out << YAML::Key << "bias_V" << YAML::Value << num(g.bias_V);
  out << YAML::Key << "axis" << YAML::Value;
  emit_vector(out, g.axis_B);
  if (g.sigma) {
    out << YAML::Key << "sigma" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "scale_factor_V_per_dps" << YAML::Value << num(g.sigma->scale_factor_V_per_dps);
    out << YAML::Key << "bias_V" << YAML::Value << num(g.sigma->bias_V);
    out << YAML::Key << "axis" << YAML::Value;
    emit_vector(out, g.sigma->axis);
    out << YAML::EndMap;
  }
  if (g.noise) {
    out << YAML::Key << "noise" << YAML::Value << YAML::BeginMap;
    const auto put = [&out](const char* key, const std::optional<double>& v) {
      if (v) out << YAML::Key << key << YAML::Value << num(*v);
    };
    put("quantization_deg", g.noise->quantization_deg);
    put("arw_dps_rtHz", g.noise->arw_dps_rtHz);
    put("bias_instability_dps", g.noise->bias_instability_dps);
    put("rate_random_walk_dps_per_rts", g.noise->rate_random_walk_dps_per_rts);
    put("rate_ramp_dps_per_s", g.noise->rate_ramp_dps_per_s);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
}

}  // namespace

std::string format_calibration(const Calibration& cal, const Metadata& comments) {
  // yaml-cpp's emitter quotes and escapes text (a unit name with a quote, a backslash or a newline
  // reads back unchanged); numbers are written in shortest round-trip form.
  YAML::Emitter out;
  out << YAML::Comment(
      "tetra calibration: y_i = (g_i - bias_V) / scale_factor_V_per_dps = axis . omega_B [deg/s]");
  for (const auto& [key, value] : comments) {
    out << YAML::Newline << YAML::Comment(key + "=" + one_line(value));
  }
  out << YAML::BeginMap;
  out << YAML::Key << "unit" << YAML::Value << YAML::DoubleQuoted << cal.unit;
  if (cal.latitude_deg) out << YAML::Key << "latitude_deg" << YAML::Value << num(*cal.latitude_deg);
  if (!cal.method.empty()) out << YAML::Key << "method" << YAML::Value << YAML::DoubleQuoted << cal.method;
  out << YAML::Key << "gyros" << YAML::Value << YAML::BeginSeq;
  for (const auto& g : cal.gyros) emit_gyro(out, g);
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

Status write_calibration(const std::string& path, const Calibration& cal) {
  return write_text_file(path, format_calibration(cal));
}

Status write_calibration(OutputFile& out, const Calibration& cal, const Metadata& comments) {
  return out.write(format_calibration(cal, comments));
}

}  // namespace tetra
