#include "tetra/ground/encode.hpp"

#include <cmath>

#include "tetra/core/geometry.hpp"
#include "tetra/core/units.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {

namespace {

using nlohmann::json;

json gyro_list(GyroMask mask, int n_gyros) {
  json ids = json::array();
  for (int g = 1; g <= n_gyros; ++g) {
    if ((mask >> static_cast<unsigned>(g - 1)) & 1U) ids.push_back(g);
  }
  return ids;
}

//! A finite number, or null (JSON has no NaN).
json number(double value) {
  return std::isfinite(value) ? json(value) : json(nullptr);
}

json vector_deg(const Eigen::Vector3d& v_rad) {
  return json::array({v_rad.x() * kRadToDeg, v_rad.y() * kRadToDeg, v_rad.z() * kRadToDeg});
}

json counters_json(const dds::HealthView& view) {
  const auto& h = view.health.counters;
  const auto& c = view.counters;
  return {{"epochs_accepted", h.epochs_accepted},
          {"epochs_rejected_time", h.epochs_rejected_time},
          {"samples_accepted", h.samples_accepted},
          {"samples_invalid", h.samples_invalid},
          {"samples_absent", h.samples_absent},
          {"samples_late", c.samples_late},
          {"samples_duplicate", c.samples_duplicate},
          {"samples_out_of_order", c.samples_out_of_order},
          {"samples_gap", c.samples_gap},
          {"deadlines_missed", c.deadlines_missed},
          {"liveliness_lost", c.liveliness_lost},
          {"unit_silences", c.unit_silences},
          {"sensor_restarts", c.sensor_restarts},
          {"time_outlier", c.time_outlier},
          {"seq_discontinuity", c.seq_discontinuity}};
}

}  // namespace

std::string json_text(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

double utc_ms(std::int64_t utc_ns) {
  return static_cast<double>(utc_ns) / 1e6;
}

EulerDeg euler_zyx_deg(const Quaternion& q_RB) {
  const Eigen::Matrix3d r = q_RB.normalized().toRotationMatrix();
  EulerDeg e;
  e.roll_deg = std::atan2(r(2, 1), r(2, 2)) * kRadToDeg;
  e.pitch_deg = std::asin(std::clamp(-r(2, 0), -1.0, 1.0)) * kRadToDeg;
  e.yaw_deg = std::atan2(r(1, 0), r(0, 0)) * kRadToDeg;
  return e;
}

bool parity_available(const fdi::Health& health) {
  return gyro_count(health.used) >= 4;
}

json health_json(const dds::HealthView& view, std::int64_t utc_ns) {
  const fdi::Health& h = view.health;
  const int n = static_cast<int>(h.gyros.size());
  json gyros = json::array();
  for (int i = 0; i < n; ++i) {
    const auto& g = h.gyros[static_cast<std::size_t>(i)];
    gyros.push_back({{"id", i + 1}, {"state", fdi::to_string(g.state)}, {"kind", fdi::to_string(g.kind)}});
  }
  const bool parity = parity_available(h);
  // With fewer than four gyros there is no parity space: the fields are null, "not available".
  const auto when_parity = [&](double value) { return parity ? number(value) : json(nullptr); };
  return {{"type", "health"},
          {"unit", view.unit},
          {"unit_id", unit_id(view.unit)},
          {"utc_ms", utc_ms(utc_ns)},
          {"sensor_time_s", ns_to_seconds(h.stamp_ns)},
          {"mode", fdi::to_string(h.mode)},
          // No epoch fused yet: the service is waiting for its gyros (not lost; no sensor time yet).
          {"waiting", h.counters.epochs_accepted == 0},
          {"gyros_used", gyro_list(h.used, n)},
          {"gyros", gyros},
          {"parity_available", parity},
          {"fdi_available", h.fdi_available},
          {"reference_state", fdi::to_string(h.reference_state)},
          {"reference_nis", number(h.reference_nis)},
          {"references_delayed", h.counters.reference_delayed},
          {"references_too_late", h.counters.reference_too_late},
          {"reference_horizon_s", view.reference_horizon_s},
          {"parity_residual", when_parity(h.parity_residual)},
          {"chi2", when_parity(h.chi2)},
          {"chi2_threshold", number(h.chi2_threshold)},
          {"cusum", when_parity(h.cusum)},
          {"cusum_threshold", number(h.cusum_threshold)},
          {"counters", counters_json(view)},
          {"events_published", view.events_published},
          {"gyro_writers", view.gyro_writers},
          {"health_period_s", view.health_period_s}};
}

json attitude_json(const std::string& unit, const fdi::AttitudeEstimate& a, std::int64_t utc_ns) {
  const auto q = to_wxyz(a.q_RB);
  const EulerDeg e = euler_zyx_deg(a.q_RB);
  return {{"type", "attitude"},
          {"unit", unit},
          {"unit_id", unit_id(unit)},
          {"utc_ms", utc_ms(utc_ns)},
          {"sensor_time_s", ns_to_seconds(a.stamp_ns)},
          {"q", json::array({q[0], q[1], q[2], q[3]})},
          {"euler_deg", {{"roll", e.roll_deg}, {"pitch", e.pitch_deg}, {"yaw", e.yaw_deg}}},
          {"rate_dps", vector_deg(a.omega_BR_B_rad_s)},
          {"sigma_deg", vector_deg(a.sigma_rad)},
          {"protection_level_deg", vector_deg(a.protection_level_rad)},
          {"mode", fdi::to_string(a.mode)},
          {"gyros_used", a.gyros},
          {"fdi_available", a.fdi_available}};
}

json event_json(const dds::EventView& view, int n_gyros, std::int64_t utc_ns) {
  json out = json::parse(fdi::to_json(view.event, n_gyros), nullptr, false);
  if (out.is_discarded()) out = json::object();
  out["type"] = "event";
  out["unit"] = view.unit;
  out["unit_id"] = unit_id(view.unit);
  out["event_seq"] = view.event_seq;
  out["utc_ms"] = utc_ms(utc_ns);
  out["sensor_time_s"] = ns_to_seconds(view.event.stamp_ns);
  if (view.command_id != 0) {
    out["command_id"] = std::to_string(view.command_id);  // 64 bits: a string, JavaScript numbers lose it
    out["command"] = dds::to_string(view.command.kind);
    out["force"] = view.command.force;
    out["operator"] = view.command.operator_id;
    out["origin"] = view.command.origin;
  }
  return out;
}

json ack_json(const dds::EventView& ack, int n_gyros) {
  json out = event_json(ack, n_gyros, 0);
  out.erase("type");
  out.erase("utc_ms");
  return out;
}

}  // namespace tetra::ground
