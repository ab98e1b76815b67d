// tetra.score: an attitude estimate against the truth (docs/score.md), from files or arrays.
#include <cmath>
#include <optional>
#include <string>

#include <pybind11/stl.h>

#include "common.hpp"
#include "tetra/core/attitude_score.hpp"

namespace tetra::python {

namespace {

using namespace pybind11::literals;

py::array_t<double> vec3(const Eigen::Vector3d& v) {
  return read_only(std::vector<double>{v.x(), v.y(), v.z()});
}

// An attitude or truth series from arrays, checked as the file reader checks a file's rows (finite,
// time increasing, quaternions of norm 1 within 1e-3, which are then normalized; sigma ≥ 0 or NaN).
AttitudeSeries series_from_arrays(const std::string& source, const py::handle& time_s,
                                  const py::handle& q_wxyz, const py::handle& rate_dps,
                                  const py::object& sigma_deg, const py::object& sigma_B_deg) {
  const DoubleArray t = doubles(time_s, "time_s", 0, Finite::kRequired);
  const DoubleArray q = doubles(q_wxyz, "q_RB_wxyz", 4, Finite::kRequired);
  const DoubleArray w = doubles(rate_dps, "omega_BR_B_dps", 3, Finite::kRequired);
  const std::size_t n = t.rows;
  if (q.rows != n || w.rows != n)
    throw py::value_error(source + ": q_RB_wxyz and omega_BR_B_dps: expected one row per time_s");
  AttitudeSeries s;
  s.source = source;
  for (std::size_t r = 0; r < n; ++r) {
    if (r > 0 && !(t.data[r] > t.data[r - 1]))
      throw py::value_error(source + ": time_s[" + std::to_string(r) + "]: time not increasing");
    const Quaternion quat = from_wxyz(q(r, 0), q(r, 1), q(r, 2), q(r, 3));
    if (std::abs(quat.norm() - 1.0) > 1e-3)
      throw py::value_error(source + ": q_RB_wxyz[" + std::to_string(r) + "]: norm is not 1 (within 1e-3)");
    s.time_s.push_back(t.data[r]);
    s.q_RB.push_back(quat.normalized());
    s.rate_B_dps.emplace_back(w(r, 0), w(r, 1), w(r, 2));
    s.lines.push_back(r + 1);
  }
  auto check_sigma = [&](double v, const char* name, std::size_t r) {
    if (std::isinf(v) || v < 0.0)
      throw py::value_error(source + ": " + name + "[" + std::to_string(r) +
                            "]: must be >= 0 (or NaN: not stated)");
  };
  if (!sigma_deg.is_none()) {
    const DoubleArray sg = doubles(sigma_deg, "sigma_deg", 0, Finite::kNanAllowed);
    if (sg.rows != n) throw py::value_error(source + ": sigma_deg: expected one value per time_s");
    for (std::size_t r = 0; r < n; ++r) {
      check_sigma(sg.data[r], "sigma_deg", r);
      s.sigma_deg.push_back(sg.data[r]);
    }
  }
  if (!sigma_B_deg.is_none()) {
    const DoubleArray sb = doubles(sigma_B_deg, "sigma_B_deg", 3, Finite::kNanAllowed);
    if (sb.rows != n) throw py::value_error(source + ": sigma_B_deg: expected one row per time_s");
    for (std::size_t r = 0; r < n; ++r) {
      for (std::size_t a = 0; a < 3; ++a) check_sigma(sb(r, a), "sigma_B_deg", r);
      s.sigma_B_deg.emplace_back(sb(r, 0), sb(r, 1), sb(r, 2));
    }
  }
  return s;
}

}  // namespace

static void bind_attitude_series(py::module_& m) {
  py::class_<AttitudeSeries>(m, "AttitudeSeries", "Rows of an attitude (estimate or truth) to score.")
      .def_readonly("source", &AttitudeSeries::source,
                    "What the rows came from (a file name or 'attitude'/'truth').")
      .def_property_readonly(
          "epochs", [](const AttitudeSeries& s) { return s.time_s.size(); }, "Rows of the series.");
  m.def(
      "_read_attitude_series",
      [](const std::string& path, bool with_sigma) { return take(read_attitude_series(path, with_sigma)); },
      "path"_a, "with_sigma"_a);
  m.def("_attitude_series", &series_from_arrays, "source"_a, "time_s"_a, "q_RB_wxyz"_a, "omega_BR_B_dps"_a,
        "sigma_deg"_a, "sigma_B_deg"_a);
}

static void bind_attitude_score(py::module_& m) {
  py::class_<AttitudeScore>(
      m, "AttitudeScore",
      "The figures of `tetra score` (docs/score.md); angles in degrees, vectors per body "
      "axis x, y, z.")
      .def_property_readonly(
          "time_s",
          [](const AttitudeScore& s) {
            std::vector<double> v;
            for (const auto& e : s.epochs) v.push_back(e.time_s);
            return read_only(std::move(v));
          },
          "[s] the scored attitude rows' times.")
      .def_property_readonly(
          "error_B_deg",
          [](const AttitudeScore& s) {
            std::vector<double> v;
            for (const auto& e : s.epochs)
              v.insert(v.end(), {e.error_B_deg.x(), e.error_B_deg.y(), e.error_B_deg.z()});
            return read_only(std::move(v), s.epochs.size(), 3);
          },
          "[deg] error e_B per scored row, (m, 3).")
      .def_property_readonly(
          "sigma_B_deg",
          [](const AttitudeScore& s) {
            std::vector<double> v;
            for (const auto& e : s.epochs)
              v.insert(v.end(), {e.sigma_B_deg.x(), e.sigma_B_deg.y(), e.sigma_B_deg.z()});
            return read_only(std::move(v), s.epochs.size(), 3);
          },
          "[deg] per-axis 1σ per scored row (NaN without per-axis columns), (m, 3).")
      .def_property_readonly(
          "sigma_deg",
          [](const AttitudeScore& s) {
            std::vector<double> v;
            for (const auto& e : s.epochs) v.push_back(e.sigma_deg);
            return read_only(std::move(v));
          },
          "[deg] total 1σ per scored row.")
      .def_readonly("exact_matches", &AttitudeScore::exact_matches,
                    "Attitude rows with a truth row within time_tolerance_s.")
      .def_readonly("interpolated", &AttitudeScore::interpolated,
                    "Attitude rows scored against truth interpolated between its rows.")
      .def_readonly("outside_truth", &AttitudeScore::outside_truth,
                    "Attitude rows before or after the truth's time span: not scored.")
      .def_readonly("per_axis_sigma", &AttitudeScore::per_axis_sigma,
                    "True when the per-axis 1σ (sigma_B_deg) was used, False: the total sigma_deg.")
      .def_property_readonly(
          "rms_B_deg", [](const AttitudeScore& s) { return vec3(s.rms_B_deg); },
          "[deg] RMS of each component of the error e_B, (3,).")
      .def_property_readonly(
          "max_abs_B_deg", [](const AttitudeScore& s) { return vec3(s.max_abs_B_deg); },
          "[deg] largest |e_a| per body axis, (3,).")
      .def_readonly("rms_total_deg", &AttitudeScore::rms_total_deg, "[deg] RMS of the error angle |e_B|.")
      .def_readonly("max_total_deg", &AttitudeScore::max_total_deg, "[deg] largest error angle |e_B|.")
      .def_readonly("final_total_deg", &AttitudeScore::final_total_deg,
                    "[deg] error angle |e_B| at the last scored row.")
      .def_readonly("sigma_epochs", &AttitudeScore::sigma_epochs, "Scored rows with a stated (positive) 1σ.")
      .def_readonly("no_sigma_epochs", &AttitudeScore::no_sigma_epochs,
                    "Scored rows with a 1σ of 0 or NaN (not in the NEES and σ fractions).")
      .def_readonly("nees_dof", &AttitudeScore::nees_dof,
                    "Degrees of freedom of the NEES: 3 with per-axis σ, 1 with the total σ.")
      .def_readonly("mean_nees", &AttitudeScore::mean_nees,
                    "Mean NEES: Σ(e_a/σ_a)² over the axes (expectation 3) or |e|²/σ² (expectation 1).")
      .def_property_readonly(
          "within_B",
          [](const AttitudeScore& s) {
            std::vector<double> v;
            for (const auto& w : s.within_B) v.insert(v.end(), {w.x(), w.y(), w.z()});
            return read_only(std::move(v), 3, 3);
          },
          "Fractions within 1, 2, 3σ (rows) per axis (columns); NaN without per-axis σ.")
      .def_property_readonly(
          "within_total",
          [](const AttitudeScore& s) {
            return read_only(std::vector<double>(s.within_total.begin(), s.within_total.end()));
          },
          "Fractions of the total angle within 1, 2, 3σ.")
      .def_property_readonly(
          "angle_B_deg", [](const AttitudeScore& s) { return vec3(s.angle_B_deg); },
          "[deg] the estimate's rate integrated per body axis, (3,).")
      .def_property_readonly(
          "truth_angle_B_deg", [](const AttitudeScore& s) { return vec3(s.truth_angle_B_deg); },
          "[deg] the same from the truth's rates, (3,).")
      .def_readonly("angle_axis_deg", &AttitudeScore::angle_axis_deg,
                    "[deg] the estimate's rate integrated about axis_B (the seed experiment's angle).")
      .def_readonly("truth_angle_axis_deg", &AttitudeScore::truth_angle_axis_deg,
                    "[deg] the same from the truth's rates.");
}

static void bind_score_function(py::module_& m) {
  m.def(
      "_score",
      [](const AttitudeSeries& attitude, const AttitudeSeries& truth, double time_tolerance_s,
         const std::vector<double>& axis_B) {
        if (axis_B.size() != 3) throw py::value_error("axis_B: expected three components");
        ScoreOptions o;
        o.time_tolerance_s = time_tolerance_s;
        o.axis_B = Eigen::Vector3d(axis_B[0], axis_B[1], axis_B[2]);
        Result<AttitudeScore> r = bad_input("");
        {
          py::gil_scoped_release release;
          r = score_attitude(attitude, truth, o);
        }
        return take(std::move(r));
      },
      "attitude"_a, "truth"_a, "time_tolerance_s"_a, "axis_B"_a);
}

void bind_score(py::module_& m) {
  bind_attitude_series(m);
  bind_attitude_score(m);
  bind_score_function(m);
}

}  // namespace tetra::python
