#include "tetra/sim/closed_loop_spec.hpp"

#include <cmath>
#include <tuple>

#include <yaml-cpp/yaml.h>
#include <Eigen/Dense>

#include "ranges.hpp"
#include "tetra/core/units.hpp"
#include "tetra/core/yaml_reader.hpp"
#include "tetra/sim/guidance.hpp"
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
  if (Status st = validate_closed_loop(spec); !st)
    return yaml.error(node_named(node, st.error().message), what, st.error().message);
  return spec;
}

namespace {

// Symmetric (to 1e-9 of its largest element), principal moments within the bounds and obeying the
// triangle inequality (each at most the sum of the other two, to 1e-9): a rigid body's inertia.
Status check_inertia(const Eigen::Matrix3d& inertia) {
  const std::string key = "inertia_kg_m2";
  if (!inertia.allFinite()) return bad_input(key + " must be finite");
  const double scale = inertia.cwiseAbs().maxCoeff();
  if (!((inertia - inertia.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale))
    return bad_input(key + " must be symmetric");
  const Eigen::Vector3d m = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvalues();
  if (!(m.minCoeff() > 0.0)) return bad_input(key + " must be positive definite");
  if (Status st = check_range(key + " principal moments", m.minCoeff(), kMinInertia_kg_m2, kMaxInertia_kg_m2,
                              "kg·m^2");
      !st)
    return st;
  if (Status st = check_range(key + " principal moments", m.maxCoeff(), kMinInertia_kg_m2, kMaxInertia_kg_m2,
                              "kg·m^2");
      !st)
    return st;
  // Eigenvalues in increasing order: the largest is the one that can break the inequality.
  if (m[2] > (m[0] + m[1]) * (1.0 + 1e-9)) {
    return bad_input(key + ": principal moments " + number_text(m[0]) + ", " + number_text(m[1]) + ", " +
                     number_text(m[2]) + " break the triangle inequality (no rigid body has them)");
  }
  return ok_status();
}

// Every component of `v` within ±max.
Status check_vector(const std::string& key, const Eigen::Vector3d& v, double max, const char* unit) {
  for (int i = 0; i < 3; ++i) {
    if (Status st = check_range(key + "[" + std::to_string(i) + "]", v[i], -max, max, unit); !st) return st;
  }
  return ok_status();
}

Status check_wheels_and_disturbance(const ClosedLoopSpec& s) {
  const WheelSpec& w = s.wheels;
  for (const auto& [key, value, max, unit] :
       {std::tuple<const char*, double, double, const char*>{"wheels.max_torque_Nm", w.max_torque_Nm,
                                                             kMaxWheelTorque_Nm, "N·m"},
        {"wheels.max_momentum_Nms", w.max_momentum_Nms, kMaxWheelMomentum_Nms, "N·m·s"},
        {"wheels.inertia_kg_m2", w.inertia_kg_m2, kMaxWheelInertia_kg_m2, "kg·m^2"}}) {
    if (Status st = check_range(key, value, 0.0, max, unit, true); !st) return st;
  }
  if (!(std::abs(w.pyramid_elevation_deg) > 1.0 && std::abs(w.pyramid_elevation_deg) < 89.0))
    return bad_input("wheels.pyramid_elevation_deg must be between 1 and 89 deg");
  if (Status st =
          check_vector("disturbance.constant_Nm", s.disturbance.constant_Nm, kMaxDisturbance_Nm, "N·m");
      !st)
    return st;
  return check_vector("disturbance.periodic_Nm", s.disturbance.periodic_Nm, kMaxDisturbance_Nm, "N·m");
}

Status check_controller(const ControllerSpec& c) {
  if (Status st = check_range("controller.bandwidth_hz", c.bandwidth_hz, 0.0, kMaxBandwidth_hz, "Hz", true);
      !st)
    return st;
  if (Status st = check_range("controller.damping", c.damping, 0.0, kMaxDamping, "", true); !st) return st;
  if (Status st = check_range("controller.integral_time_s", c.integral_time_s, 0.0, kMaxControlTime_s, "s");
      !st)
    return st;
  if (Status st = check_range("controller.hold_after_s", c.hold_after_s, 0.0, kMaxControlTime_s, "s", true);
      !st)
    return st;
  if (!(c.safe_after_s >= c.hold_after_s && c.safe_after_s <= kMaxControlTime_s))
    return bad_input("controller: need 0 < hold_after_s <= safe_after_s <= " +
                     number_text(kMaxControlTime_s));
  return ok_status();
}

Status check_pointing(const ClosedLoopSpec& s) {
  const PointingSpec& p = s.pointing;
  if (Status st =
          check_range("pointing.max_rate_dps", p.max_rate_dps, 0.0, kMaxPointingRate_dps, "deg/s", true);
      !st)
    return st;
  if (Status st = check_range("pointing.max_accel_dps2", p.max_accel_dps2, 0.0, kMaxPointingAccel_dps2,
                              "deg/s^2", true);
      !st)
    return st;
  // Each slew's trapezoid keeps within max_rate_dps and max_accel_dps2 by itself; two under way at
  // once would add their rates and accelerations, so a slew starts when the one before has ended.
  double previous_start = -INFINITY;
  double previous_end = -INFINITY;
  for (std::size_t i = 0; i < p.slews.size(); ++i) {
    const PointingSlew& slew = p.slews[i];
    const std::string key = "pointing.slews[" + std::to_string(i) + "]";
    if (Status st = check_range(key + ".angle_deg", slew.angle_deg, -kMaxPointingAngle_deg,
                                kMaxPointingAngle_deg, "deg");
        !st)
      return st;
    if (!std::isfinite(slew.start_s) || slew.start_s < previous_start)
      return bad_input(key + ".start_s must be finite and in order");
    if (slew.start_s < previous_end) {
      return bad_input(key + ".start_s " + number_text(slew.start_s) + " s: slews[" + std::to_string(i - 1) +
                       "] is still under way until " + number_text(previous_end) +
                       " s (its trapezoid at max_rate_dps " + number_text(p.max_rate_dps) +
                       " and max_accel_dps2 " + number_text(p.max_accel_dps2) +
                       "); overlapping slews would add their rates and accelerations beyond those limits");
    }
    previous_start = slew.start_s;
    previous_end = slew.start_s + trapezoid_duration_s(slew.angle_deg * kDegToRad, p.max_rate_dps * kDegToRad,
                                                       p.max_accel_dps2 * kDegToRad);
  }
  if (Status st = check_range("pointing_bound_deg", s.pointing_bound_deg, 0.0, 180.0, "deg", true); !st)
    return st;
  if (Status st = check_range("initial_error_deg (its norm)", s.initial_error_deg.norm(), 0.0, 180.0, "deg");
      !st)
    return st;
  return check_range("initial_rate_error_dps (its norm)", s.initial_rate_error_dps.norm(), 0.0,
                     kMaxPointingRate_dps, "deg/s");
}

}  // namespace

Status validate_closed_loop(const ClosedLoopSpec& s) {
  if (Status st = check_inertia(s.inertia_kg_m2); !st) return st;
  if (Status st = check_range("dynamics_hz", s.dynamics_hz, 0.0, 1.0e5, "Hz", true); !st) return st;
  if (Status st = check_wheels_and_disturbance(s); !st) return st;
  if (Status st = check_controller(s.controller); !st) return st;
  return check_pointing(s);
}

}  // namespace tetra::sim
