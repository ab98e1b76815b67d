#include "tetra/sim/closed_loop_spec.hpp"

#include <cmath>

#include <yaml-cpp/yaml.h>
#include <Eigen/Dense>

#include "tetra/core/units.hpp"
#include "tetra/core/yaml_reader.hpp"
#include "text.hpp"
#include "yaml_fields.hpp"

namespace tetra::sim {

namespace {

// Inertia: [Ixx, Iyy, Izz] (principal) or a 3×3 list of rows.
Result<Eigen::Matrix3d> parse_inertia(const YamlReader& yaml, const YAML::Node& node,
                                      const std::string& what) {
  if (node.IsSequence() && node.size() == 3 && node[0].IsSequence()) {
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r) {
      auto row = yaml.vector3(node[static_cast<std::size_t>(r)], what + "[" + std::to_string(r) + "]");
      if (!row) return row.error();
      m.row(r) = row->transpose();
    }
    return m;
  }
  auto diag = yaml.vector3(node, what);
  if (!diag) return diag.error();
  return Eigen::Matrix3d(diag->asDiagonal());
}

Status maybe_vector3(const YamlReader& yaml, const YAML::Node& parent, const std::string& key,
                     const std::string& what, Eigen::Vector3d& out) {
  if (!parent[key]) return ok_status();
  auto v = yaml.vector3(parent[key], YamlReader::child(what, key));
  if (!v) return v.error();
  out = *v;
  return ok_status();
}

Status parse_wheels(const YamlReader& yaml, const YAML::Node& node, WheelSpec& w) {
  const std::string what = "closed_loop.wheels";
  if (Status st = yaml.check_keys(
          node, {"count", "max_torque_Nm", "max_momentum_Nms", "inertia_kg_m2", "pyramid_elevation_deg"},
          what);
      !st)
    return st;
  double count = w.count;
  if (Status st = maybe_numbers(yaml, node, what,
                                {{"count", &count},
                                 {"max_torque_Nm", &w.max_torque_Nm},
                                 {"max_momentum_Nms", &w.max_momentum_Nms},
                                 {"inertia_kg_m2", &w.inertia_kg_m2},
                                 {"pyramid_elevation_deg", &w.pyramid_elevation_deg}});
      !st)
    return st;
  if (count != 3.0 && count != 4.0) return yaml.error(node["count"], what + ".count", "must be 3 or 4");
  w.count = static_cast<int>(count);
  return ok_status();
}

Status parse_disturbance(const YamlReader& yaml, const YAML::Node& node, DisturbanceSpec& d) {
  const std::string what = "closed_loop.disturbance";
  if (Status st = yaml.check_keys(node, {"constant_Nm", "periodic_Nm", "gravity_gradient"}, what); !st)
    return st;
  if (Status st = maybe_vector3(yaml, node, "constant_Nm", what, d.constant_Nm); !st) return st;
  if (Status st = maybe_vector3(yaml, node, "periodic_Nm", what, d.periodic_Nm); !st) return st;
  if (const YAML::Node gg = node["gravity_gradient"]) {
    if (!YAML::convert<bool>::decode(gg, d.gravity_gradient))
      return yaml.error(gg, what + ".gravity_gradient", "expected true or false");
  }
  return ok_status();
}

Status parse_controller(const YamlReader& yaml, const YAML::Node& node, ControllerSpec& c) {
  const std::string what = "closed_loop.controller";
  if (Status st = yaml.check_keys(
          node, {"bandwidth_hz", "damping", "integral_time_s", "hold_after_s", "safe_after_s"}, what);
      !st)
    return st;
  return maybe_numbers(yaml, node, what,
                       {{"bandwidth_hz", &c.bandwidth_hz},
                        {"damping", &c.damping},
                        {"integral_time_s", &c.integral_time_s},
                        {"hold_after_s", &c.hold_after_s},
                        {"safe_after_s", &c.safe_after_s}});
}

Result<PointingSlew> parse_pointing_slew(const YamlReader& yaml, const YAML::Node& s,
                                         const std::string& what) {
  if (Status st = yaml.check_keys(s, {"axis", "angle_deg", "start_s"}, what); !st) return st.error();
  for (const char* key : {"axis", "angle_deg", "start_s"}) {
    if (!s[key]) return yaml.error(s, what + "." + key, "missing");
  }
  PointingSlew slew;
  auto axis = axis_from(yaml, s["axis"], what + ".axis");
  if (!axis) return axis.error();
  slew.axis_R = *axis;
  if (Status st = maybe_numbers(yaml, s, what, {{"angle_deg", &slew.angle_deg}, {"start_s", &slew.start_s}});
      !st)
    return st.error();
  return slew;
}

Status parse_pointing(const YamlReader& yaml, const YAML::Node& node, PointingSpec& p) {
  const std::string what = "closed_loop.pointing";
  if (Status st =
          yaml.check_keys(node, {"mode", "target_q_NR", "slews", "max_rate_dps", "max_accel_dps2"}, what);
      !st)
    return st;
  if (const YAML::Node mode = node["mode"]) {
    const std::string name = mode.as<std::string>();
    if (name == "nadir") {
      p.mode = PointingMode::kNadir;
    } else if (name == "inertial") {
      p.mode = PointingMode::kInertial;
    } else {
      return yaml.error(mode, what + ".mode", "'" + name + "' is not a pointing mode (nadir, inertial)");
    }
  }
  if (const YAML::Node q = node["target_q_NR"]) {
    if (!q.IsSequence() || q.size() != 4)
      return yaml.error(q, what + ".target_q_NR", "expected [w, x, y, z]");
    std::array<double, 4> c{};
    for (std::size_t i = 0; i < 4; ++i) {
      auto v = yaml.number(q[i], what + ".target_q_NR");
      if (!v) return v.error();
      c[i] = *v;
    }
    const Quaternion target = from_wxyz(c);
    if (target.norm() < 1e-9) return yaml.error(q, what + ".target_q_NR", "must not be zero");
    p.q_NR0 = canonical(target);
  }
  if (const YAML::Node slews = node["slews"]) {
    if (!slews.IsSequence()) return yaml.error(slews, what + ".slews", "expected a list");
    for (std::size_t i = 0; i < slews.size(); ++i) {
      auto slew = parse_pointing_slew(yaml, slews[i], what + ".slews[" + std::to_string(i) + "]");
      if (!slew) return slew.error();
      p.slews.push_back(*slew);
    }
  }
  return maybe_numbers(yaml, node, what,
                       {{"max_rate_dps", &p.max_rate_dps}, {"max_accel_dps2", &p.max_accel_dps2}});
}

}  // namespace

std::string_view pointing_mode_name(PointingMode mode) {
  return mode == PointingMode::kNadir ? "nadir" : "inertial";
}

Result<ClosedLoopSpec> parse_closed_loop(const YamlReader& yaml, const YAML::Node& node) {
  const std::string what = "closed_loop";
  if (Status st =
          yaml.check_keys(node,
                          {"inertia_kg_m2", "dynamics_hz", "wheels", "disturbance", "controller", "pointing",
                           "initial_error_deg", "initial_rate_error_dps", "pointing_bound_deg"},
                          what);
      !st)
    return st.error();
  ClosedLoopSpec spec;
  if (const YAML::Node inertia = node["inertia_kg_m2"]) {
    auto m = parse_inertia(yaml, inertia, what + ".inertia_kg_m2");
    if (!m) return m.error();
    spec.inertia_kg_m2 = *m;
  }
  if (Status st = maybe_numbers(
          yaml, node, what,
          {{"dynamics_hz", &spec.dynamics_hz}, {"pointing_bound_deg", &spec.pointing_bound_deg}});
      !st)
    return st.error();
  if (Status st = maybe_vector3(yaml, node, "initial_error_deg", what, spec.initial_error_deg); !st)
    return st.error();
  if (Status st = maybe_vector3(yaml, node, "initial_rate_error_dps", what, spec.initial_rate_error_dps); !st)
    return st.error();
  if (node["wheels"]) {
    if (Status st = parse_wheels(yaml, node["wheels"], spec.wheels); !st) return st.error();
  }
  if (node["disturbance"]) {
    if (Status st = parse_disturbance(yaml, node["disturbance"], spec.disturbance); !st) return st.error();
  }
  if (node["controller"]) {
    if (Status st = parse_controller(yaml, node["controller"], spec.controller); !st) return st.error();
  }
  if (node["pointing"]) {
    if (Status st = parse_pointing(yaml, node["pointing"], spec.pointing); !st) return st.error();
  }
  if (Status st = validate_closed_loop(spec); !st) return yaml.error(node, what, st.error().message);
  return spec;
}

Status validate_closed_loop(const ClosedLoopSpec& s) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(s.inertia_kg_m2);
  if (!s.inertia_kg_m2.allFinite() || !s.inertia_kg_m2.isApprox(s.inertia_kg_m2.transpose()) ||
      eig.eigenvalues().minCoeff() <= 0.0) {
    return bad_input("inertia_kg_m2 must be symmetric positive definite");
  }
  if (!positive(s.dynamics_hz) || s.dynamics_hz > 1.0e5) return bad_input("dynamics_hz must be in (0, 1e5]");
  if (!positive(s.pointing_bound_deg)) return bad_input("pointing_bound_deg must be positive");
  if (!positive(s.wheels.max_torque_Nm) || !positive(s.wheels.max_momentum_Nms) ||
      !positive(s.wheels.inertia_kg_m2))
    return bad_input("wheels: max_torque_Nm, max_momentum_Nms and inertia_kg_m2 must be positive");
  if (!(std::abs(s.wheels.pyramid_elevation_deg) > 1.0 && std::abs(s.wheels.pyramid_elevation_deg) < 89.0))
    return bad_input("wheels.pyramid_elevation_deg must be between 1 and 89 deg");
  const ControllerSpec& c = s.controller;
  if (!positive(c.bandwidth_hz) || !positive(c.damping))
    return bad_input("controller: bandwidth_hz and damping must be positive");
  if (!std::isfinite(c.integral_time_s) || c.integral_time_s < 0.0)
    return bad_input("controller.integral_time_s must not be negative");
  if (!positive(c.hold_after_s) || !(c.safe_after_s >= c.hold_after_s))
    return bad_input("controller: need 0 < hold_after_s <= safe_after_s");
  if (!positive(s.pointing.max_rate_dps) || !positive(s.pointing.max_accel_dps2))
    return bad_input("pointing: max_rate_dps and max_accel_dps2 must be positive");
  double previous_start = -INFINITY;
  for (const PointingSlew& slew : s.pointing.slews) {
    if (!std::isfinite(slew.angle_deg) || !std::isfinite(slew.start_s) || slew.start_s < previous_start)
      return bad_input("pointing.slews: start_s must be finite and in order");
    previous_start = slew.start_s;
  }
  if (!s.initial_error_deg.allFinite() || !s.initial_rate_error_dps.allFinite())
    return bad_input("initial_error_deg and initial_rate_error_dps must be finite");
  return ok_status();
}

}  // namespace tetra::sim
