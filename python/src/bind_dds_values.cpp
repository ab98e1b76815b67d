// tetra.dds's values (dds_values.hpp): the wire's views as dicts in SI units.
#include "dds_values.hpp"

#include <vector>

#include "events.hpp"

namespace tetra::python {

namespace {

using namespace pybind11::literals;

py::array_t<double> vector3(const Eigen::Vector3d& v) {
  return to_numpy(std::vector<double>{v[0], v[1], v[2]});
}

py::dict counters_dict(const dds::HealthView& h) {
  const auto& p = h.health.counters;
  const auto& c = h.counters;
  return py::dict("epochs_accepted"_a = p.epochs_accepted, "epochs_rejected_time"_a = p.epochs_rejected_time,
                  "samples_accepted"_a = p.samples_accepted, "samples_invalid"_a = p.samples_invalid,
                  "samples_absent"_a = p.samples_absent, "samples_late"_a = c.samples_late,
                  "samples_duplicate"_a = c.samples_duplicate,
                  "samples_out_of_order"_a = c.samples_out_of_order, "samples_gap"_a = c.samples_gap,
                  "samples_unknown_gyro"_a = c.samples_unknown_gyro,
                  "samples_other_unit"_a = c.samples_other_unit, "sensor_restarts"_a = c.sensor_restarts,
                  "deadlines_missed"_a = c.deadlines_missed, "liveliness_lost"_a = c.liveliness_lost,
                  "time_outlier"_a = c.time_outlier, "seq_discontinuity"_a = c.seq_discontinuity,
                  "unit_silences"_a = c.unit_silences);
}

}  // namespace

py::dict wire_attitude_dict(const fdi::AttitudeEstimate& a, int n_gyros) {
  py::dict d;
  d["stamp_ns"] = a.stamp_ns;
  d["time_s"] = static_cast<double>(a.stamp_ns) * 1e-9;
  const auto q = to_wxyz(a.q_RB);
  d["q_RB_wxyz"] = to_numpy(std::vector<double>(q.begin(), q.end()));
  d["omega_BR_B_rad_s"] = vector3(a.omega_BR_B_rad_s);
  d["sigma_rad"] = vector3(a.sigma_rad);
  d["protection_level_rad"] = vector3(a.protection_level_rad);
  d["mode"] = fdi::to_string(a.mode);
  d["gyros"] = gyro_ids(a.gyros, n_gyros);
  d["gyros_mask"] = a.gyros;
  d["fdi_available"] = a.fdi_available;
  return d;
}

py::dict wire_health_dict(const dds::HealthView& v) {
  const fdi::Health& h = v.health;
  py::dict d = health_state_dict(h, static_cast<int>(h.gyros.size()));
  d["unit"] = v.unit;
  d["stamp_ns"] = h.stamp_ns;
  d["time_s"] = static_cast<double>(h.stamp_ns) * 1e-9;
  d["parity_residual"] = h.parity_residual;
  d["reference_nis"] = h.reference_nis;
  d["protection_level_rad"] = vector3(h.protection_level_rad);
  d["references_delayed"] = h.counters.reference_delayed;
  d["references_too_late"] = h.counters.reference_too_late;
  d["reference_horizon_s"] = v.reference_horizon_s;
  d["counters"] = counters_dict(v);
  d["events_published"] = v.events_published;
  d["gyro_writers"] = v.gyro_writers;
  d["health_period_s"] = v.health_period_s;
  return d;
}

py::dict wire_event_dict(const dds::EventView& v, int n_gyros) {
  py::dict d = event_dict(v.event, n_gyros);
  d["unit"] = v.unit;
  d["event_seq"] = v.event_seq;
  d["command_id"] = v.command_id;
  if (v.command_id != 0) {
    d["force"] = v.command.force;
    d["refused"] = v.event.refused();
    d["operator"] = v.command.operator_id;
    d["origin"] = v.command.origin;
  }
  return d;
}

}  // namespace tetra::python
