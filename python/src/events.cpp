#include "events.hpp"

namespace tetra::python {

py::list gyro_ids(GyroMask mask, int n_gyros) {
  py::list ids;
  for (int i = 1; i <= n_gyros; ++i)
    if (has_gyro(mask, i)) ids.append(i);
  return ids;
}

py::dict event_dict(const fdi::FdiEvent& e, int n_gyros) {
  py::dict d;
  d["stamp_ns"] = e.stamp_ns;
  d["time_s"] = static_cast<double>(e.stamp_ns) * 1e-9;
  d["type"] = fdi::to_string(e.type);
  d["gyro"] = e.gyro ? py::object(py::int_(*e.gyro)) : py::object(py::none());
  d["test"] = fdi::to_string(e.test);
  d["statistic"] = e.statistic;
  d["kind"] = fdi::to_string(e.kind);
  d["evidence"] = fdi::to_string(e.evidence);
  d["gyros"] = gyro_ids(e.gyros, n_gyros);
  d["command"] = e.command ? py::object(py::str(fdi::to_string(*e.command))) : py::object(py::none());
  d["outcome"] = fdi::to_string(e.outcome);
  d["why"] = fdi::to_string(e.why);
  d["detail"] = e.detail;
  d["json"] = fdi::to_json(e, n_gyros);
  return d;
}

py::dict health_state_dict(const fdi::Health& h, int n_gyros) {
  using namespace pybind11::literals;
  py::dict d;
  d["mode"] = fdi::to_string(h.mode);
  d["used"] = gyro_ids(h.used, n_gyros);
  py::list gyros;
  for (const auto& g : h.gyros) {
    gyros.append(py::dict("state"_a = fdi::to_string(g.state), "kind"_a = fdi::to_string(g.kind),
                          "bias_rad_s"_a = g.bias_rad_s, "bias_sigma_rad_s"_a = g.bias_sigma_rad_s));
  }
  d["gyros"] = gyros;
  d["chi2"] = h.chi2;
  d["cusum"] = h.cusum;
  d["chi2_threshold"] = h.chi2_threshold;
  d["cusum_threshold"] = h.cusum_threshold;
  d["fdi_available"] = h.fdi_available;
  d["reference_state"] = fdi::to_string(h.reference_state);
  return d;
}

}  // namespace tetra::python
