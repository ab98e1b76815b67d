// tetra.allan (arrays in) and tetra.allan_log (a log file, as `tetra allan` reads it).
#include <cmath>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <pybind11/stl.h>

#include "common.hpp"
#include "tetra/core/allan.hpp"
#include "tetra/core/calibration_file.hpp"
#include "watch.hpp"

namespace tetra::python {

namespace {

using namespace pybind11::literals;

allan::TauSpec tau_spec(const std::variant<std::string, std::vector<double>>& taus) {
  if (const auto* text = std::get_if<std::string>(&taus)) {
    Result<allan::TauSpec> spec = allan::parse_tau_spec(*text);
    return take(std::move(spec));
  }
  allan::TauSpec spec;
  spec.spacing = allan::TauSpacing::kList;
  spec.list_s = std::get<std::vector<double>>(taus);
  for (const double t : spec.list_s) {
    if (!std::isfinite(t) || t <= 0.0)
      throw py::value_error("taus: every averaging time must be a positive number");
  }
  return spec;
}

py::dict term_dict(const std::array<double, allan::kTermCount>& values) {
  py::dict d;
  for (int k = 0; k < allan::kTermCount; ++k) d[allan::term_symbol(k)] = values[static_cast<std::size_t>(k)];
  return d;
}

template <class F>
py::array_t<double> point_column(const allan::AllanResult& r, F f) {
  std::vector<double> v;
  v.reserve(r.points.size());
  for (const auto& p : r.points) v.push_back(f(p));
  return read_only(std::move(v));
}

void bind_fit(py::module_& m) {
  py::class_<allan::NoiseFit>(m, "NoiseFit",
                              "The IEEE 952 terms fitted to σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + "
                              "R²τ²/2 (docs/allan.md); units from the rate's: Q [u·s], N [u·√s], B [u], "
                              "K [u/√s], R [u/s].")
      .def_property_readonly(
          "value", [](const allan::NoiseFit& f) { return term_dict(f.value); },
          "Every fitted term by symbol ('Q', 'N', 'B', 'K', 'R'), observed or not.")
      .def_property_readonly(
          "observed",
          [](const allan::NoiseFit& f) {
            py::dict d;
            for (int k = 0; k < allan::kTermCount; ++k)
              d[allan::term_symbol(k)] = f.observed[static_cast<std::size_t>(k)];
            return d;
          },
          "Whether the data need each term (the others cannot stand in for it).")
      .def_property_readonly(
          "reported",
          [](const allan::NoiseFit& f) {
            py::dict d;
            for (int k = 0; k < allan::kTermCount; ++k) d[allan::term_symbol(k)] = f.reported(k);
            return d;
          },
          "The terms as `tetra allan` reports them: the value, or None when not observed.")
      .def_property_readonly(
          "dominant_from_s", [](const allan::NoiseFit& f) { return term_dict(f.dominant_from_s); },
          "[s] first τ where each term dominates (0 if never).")
      .def_property_readonly(
          "dominant_to_s", [](const allan::NoiseFit& f) { return term_dict(f.dominant_to_s); },
          "[s] last τ where each term dominates (0 if never).")
      .def_readonly("points_used", &allan::NoiseFit::points_used, "Points of the curve that entered the fit.")
      .def(
          "model_adev",
          [](const allan::NoiseFit& f, const py::handle& tau_s) {
            const DoubleArray t = doubles(tau_s, "tau_s", 0, Finite::kRequired);
            std::vector<double> out(t.rows);
            for (std::size_t k = 0; k < t.rows; ++k) out[k] = std::sqrt(f.model_avar(t.data[k]));
            return to_numpy(std::move(out));
          },
          "tau_s"_a, "The fitted model's Allan deviation at each τ [s] (every fitted term).");
}

void bind_result(py::module_& m) {
  py::class_<allan::AllanResult>(m, "AllanResult",
                                 "One series' overlapping Allan deviation with its confidence interval, "
                                 "and the fitted noise terms. Arrays have one entry per averaging time.")
      .def_readonly("tau0_s", &allan::AllanResult::tau0_s, "[s] the sampling interval.")
      .def_readonly("samples", &allan::AllanResult::samples, "Rate samples on the grid (gaps included).")
      .def_readonly("present_samples", &allan::AllanResult::present_samples, "Samples delivered and finite.")
      .def_property_readonly(
          "tau_s",
          [](const allan::AllanResult& r) { return point_column(r, [](const auto& p) { return p.tau_s; }); },
          "[s] averaging times.")
      .def_property_readonly(
          "adev",
          [](const allan::AllanResult& r) { return point_column(r, [](const auto& p) { return p.adev; }); },
          "Overlapping Allan deviation [rate unit].")
      .def_property_readonly(
          "adev_lo",
          [](const allan::AllanResult& r) {
            return point_column(r, [](const auto& p) { return p.adev_lo; });
          },
          "Lower confidence bound.")
      .def_property_readonly(
          "adev_hi",
          [](const allan::AllanResult& r) {
            return point_column(r, [](const auto& p) { return p.adev_hi; });
          },
          "Upper confidence bound.")
      .def_property_readonly(
          "edf",
          [](const allan::AllanResult& r) { return point_column(r, [](const auto& p) { return p.edf; }); },
          "Equivalent degrees of freedom.")
      .def_property_readonly(
          "terms",
          [](const allan::AllanResult& r) {
            std::vector<std::int64_t> v;
            for (const auto& p : r.points) v.push_back(p.terms);
            return read_only(std::move(v));
          },
          "Second differences used at each τ.")
      .def_property_readonly(
          "noise_type",
          [](const allan::AllanResult& r) {
            std::vector<std::string> v;
            for (const auto& p : r.points) v.emplace_back(noise_type_name(p.noise));
            return v;
          },
          "The noise type assumed for the EDF at each τ.")
      .def_readonly("uncomputed_tau_s", &allan::AllanResult::uncomputed_tau_s,
                    "[s] requested averaging times the gaps left without any term.")
      .def_readonly("fit", &allan::AllanResult::fit, "The fitted noise terms (tetra.NoiseFit).");
}

void bind_log_allan(py::module_& m) {
  py::class_<allan::GyroAllan>(m, "GyroAllan", "One gyro of a log's analysis.")
      .def_readonly("id", &allan::GyroAllan::id, "1..N")
      .def_readonly("absent", &allan::GyroAllan::absent,
                    "Samples not delivered (empty cells, missing epochs).")
      .def_readonly("invalid", &allan::GyroAllan::invalid, "Samples delivered as NaN or infinite.")
      .def_readonly("result", &allan::GyroAllan::result, "Its tetra.AllanResult.");
  py::class_<allan::LogAllan>(m, "LogAllan", "The analysis of a log's gyros, as `tetra allan` makes it.")
      .def_readonly("units", &allan::LogAllan::units, "'deg/s' or 'V'.")
      .def_readonly("log_units_dps", &allan::LogAllan::log_units_dps, "The log itself was in deg/s.")
      .def_readonly("tau0_s", &allan::LogAllan::tau0_s, "[s] the sampling interval.")
      .def_readonly("epochs", &allan::LogAllan::epochs, "Rows of the log.")
      .def_readonly("missing_epochs", &allan::LogAllan::missing_epochs, "Grid slots without a row.")
      .def_readonly("gyros", &allan::LogAllan::gyros, "One tetra.GyroAllan per gyro analysed.")
      .def(
          "to_csv", [](const allan::LogAllan& a) { return allan::format_csv(a); },
          "The CSV of `tetra allan --csv` (gyro,tau_s,adev,adev_lo,adev_hi,n).")
      .def(
          "to_json", [](const allan::LogAllan& a) { return allan::format_json(a); },
          "The JSON of `tetra allan --json` (without provenance).")
      .def(
          "table", [](const allan::LogAllan& a) { return allan::format_table(a); },
          "The table `tetra allan` prints.")
      .def(
          "update_calibration",
          [](const allan::LogAllan& a, Calibration cal) {
            check(allan::update_calibration_noise(cal, a));
            return cal;
          },
          "calibration"_a,
          "A copy of `calibration` with these noise terms in its 'noise:' sections (deg/s analyses only).");
}

}  // namespace

void bind_allan(py::module_& m) {
  bind_fit(m);
  bind_result(m);
  bind_log_allan(m);
  m.def(
      "_allan_series",
      [](const py::handle& rate, double tau0_s, const py::object& present,
         const std::variant<std::string, std::vector<double>>& taus, double confidence,
         const py::object& progress) {
        const DoubleArray y = doubles(rate, "rate", 0, Finite::kNanAllowed);
        MaskArray p;
        if (!present.is_none()) p = mask(present, "present", y.rows, 0);
        if (!std::isfinite(tau0_s) || tau0_s <= 0.0)
          throw py::value_error("tau0_s: must be a positive number");
        allan::AllanOptions options;
        options.taus = tau_spec(taus);
        options.confidence = confidence;
        Watch watch(progress);
        Interrupt interrupt = watch.interrupt();
        options.interrupt = &interrupt;
        Result<allan::AllanResult> r = bad_input("");
        {
          py::gil_scoped_release release;
          const std::span<const std::uint8_t> present_span =
              p.data != nullptr ? std::span<const std::uint8_t>(p.data, y.rows)
                                : std::span<const std::uint8_t>();
          r = allan::analyze_series(std::span<const double>(y.data, y.rows), present_span, tau0_s, options);
        }
        watch.raise_if_stopped();
        allan::AllanResult result = take(std::move(r));
        const std::size_t taus_done = result.points.size() + result.uncomputed_tau_s.size();
        watch.done(taus_done, taus_done);
        return result;
      },
      "rate"_a, "tau0_s"_a, "present"_a, "taus"_a, "confidence"_a, "progress"_a);
  m.def(
      "_allan_log",
      [](const std::string& path, const Calibration* calibration, const std::vector<int>& gyros,
         const std::variant<std::string, std::vector<double>>& taus, double confidence, double dt_tolerance) {
        allan::LogAllanOptions options;
        options.allan.taus = tau_spec(taus);
        options.allan.confidence = confidence;
        options.dt_tolerance = dt_tolerance;
        options.gyros = gyros;
        options.calibration = calibration;
        Result<allan::LogAllan> r = bad_input("");
        {
          py::gil_scoped_release release;
          r = allan::analyze_gyro_log_file(path, options);
        }
        return take(std::move(r));
      },
      "path"_a, "calibration"_a, "gyros"_a, "taus"_a, "confidence"_a, "dt_tolerance"_a);
  m.attr("ONE_SIGMA_CONFIDENCE") = allan::kOneSigmaConfidence;
}

}  // namespace tetra::python
