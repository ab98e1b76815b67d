// tetra.Calibration (calibration files) and tetra.calibrate (turntable calibration, from a file or arrays).
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "common.hpp"
#include "tetra/core/calibration.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/turntable_rows.hpp"

namespace tetra::python {

namespace {

using namespace pybind11::literals;

// One value per gyro as a 1-D array.
template <class F>
py::array_t<double> per_gyro(const Calibration& cal, F value) {
  std::vector<double> out;
  for (const auto& g : cal.gyros) out.push_back(value(g));
  return read_only(std::move(out));
}

// N×3 rows per gyro.
template <class F>
py::array_t<double> per_gyro_vec3(const Calibration& cal, F vec) {
  std::vector<double> out;
  for (const auto& g : cal.gyros) {
    const Eigen::Vector3d v = vec(g);
    out.insert(out.end(), {v.x(), v.y(), v.z()});
  }
  return read_only(std::move(out), cal.gyros.size(), 3);
}

bool all_have_sigma(const Calibration& cal) {
  if (cal.gyros.empty()) return false;
  for (const auto& g : cal.gyros)
    if (!g.sigma) return false;
  return true;
}

py::object noise_dict(const std::optional<GyroNoise>& n) {
  if (!n) return py::none();
  py::dict d;
  d["quantization_deg"] = n->quantization_deg;
  d["arw_dps_rtHz"] = n->arw_dps_rtHz;
  d["bias_instability_dps"] = n->bias_instability_dps;
  d["rate_random_walk_dps_per_rts"] = n->rate_random_walk_dps_per_rts;
  d["rate_ramp_dps_per_s"] = n->rate_ramp_dps_per_s;
  return d;
}

Calibration calibration_from_arrays(const py::handle& scale, const py::handle& bias, const py::handle& axes,
                                    const std::string& unit, const std::string& method) {
  const DoubleArray s = doubles(scale, "scale_factor_V_per_dps", 0, Finite::kRequired);
  const DoubleArray b = doubles(bias, "bias_V", 0, Finite::kRequired);
  const DoubleArray h = doubles(axes, "axes_B", 3, Finite::kRequired);
  if (b.rows != s.rows || h.rows != s.rows) {
    throw py::value_error("bias_V and axes_B: expected one row per gyro like scale_factor_V_per_dps (" +
                          std::to_string(s.rows) + ")");
  }
  Calibration cal;
  cal.unit = unit;
  cal.method = method;
  for (std::size_t i = 0; i < s.rows; ++i) {
    GyroCalibration g;
    g.id = static_cast<int>(i + 1);
    g.scale_factor_V_per_dps = s.data[i];
    g.bias_V = b.data[i];
    g.axis_B = Eigen::Vector3d(h(i, 0), h(i, 1), h(i, 2));
    cal.gyros.push_back(g);
  }
  check(validate_calibration(cal, "calibration"));
  for (auto& g : cal.gyros) g.axis_B.normalize();  // as the file reader does within its 1e-3
  return cal;
}

// A turntable log held in numpy arrays (views; the rows of g_V are read in place), checked as the file
// reader checks a file (finite numbers, positive integral sequences, increasing time).
class ArrayTurntableRows final : public TurntableRows {
 public:
  ArrayTurntableRows(const py::handle& sequence, const py::handle& time_s, const py::handle& inner_deg,
                     const py::handle& outer_deg, const py::handle& g_V)
      : sequence_(doubles(sequence, "sequence", 0, Finite::kRequired)),
        time_(doubles(time_s, "time_s", 0, Finite::kRequired)),
        inner_(doubles(inner_deg, "inner_deg", 0, Finite::kRequired)),
        outer_(doubles(outer_deg, "outer_deg", 0, Finite::kRequired)),
        g_(doubles(g_V, "g_V", -1, Finite::kRequired)) {
    const std::size_t n = time_.rows;
    if (sequence_.rows != n || inner_.rows != n || outer_.rows != n || g_.rows != n) {
      throw py::value_error("sequence, inner_deg, outer_deg and g_V: expected one row per time_s (" +
                            std::to_string(n) + ")");
    }
    if (g_.cols < 3)
      throw py::value_error("g_V: expected at least 3 gyro columns, got " + std::to_string(g_.cols));
    for (std::size_t r = 0; r < n; ++r) {
      const double q = sequence_.data[r];
      if (q < 1.0 || q != std::floor(q) || q > 1e9)
        throw py::value_error("sequence[" + std::to_string(r) + "]: must be a positive integer");
      if (r > 0 && !(time_.data[r] > time_.data[r - 1]))
        throw py::value_error("time_s[" + std::to_string(r) + "]: time goes backwards or repeats");
    }
  }
  const std::string& source() const override { return source_; }
  int gyro_count() const override { return static_cast<int>(g_.cols); }
  std::size_t rows() const override { return time_.rows; }
  const Metadata& metadata() const override { return metadata_; }
  Status for_each(const TurntableRowVisitor& visit) const override {
    TurntableRow row;
    for (std::size_t r = 0; r < time_.rows; ++r) {
      row.index = r;
      row.line = r + 1;
      row.sequence = static_cast<int>(sequence_.data[r]);
      row.time_s = time_.data[r];
      row.inner_deg = inner_.data[r];
      row.outer_deg = outer_.data[r];
      row.g_V = g_.data + r * g_.cols;
      visit(row);
    }
    return ok_status();
  }

 private:
  std::string source_ = "turntable arrays";
  Metadata metadata_;
  DoubleArray sequence_, time_, inner_, outer_, g_;
};

CalibrationOptions calibration_options(const std::string& method, const std::string& bias_model,
                                       const Calibration* noise, double correlation_s, int gyros) {
  CalibrationOptions o;
  if (method != "sixteen" && method != "batch")
    throw py::value_error("method: expected 'sixteen' or 'batch', got '" + method + "'");
  if (bias_model != "body" && bias_model != "seed")
    throw py::value_error("bias_model: expected 'body' or 'seed', got '" + bias_model + "'");
  o.method = method == "batch" ? CalibrationMethod::kBatch : CalibrationMethod::kSixteen;
  o.bias_model = bias_model == "seed" ? BiasModel::kSeed : BiasModel::kBody;
  if (o.method == CalibrationMethod::kBatch && o.bias_model != BiasModel::kBody)
    throw py::value_error("bias_model: applies to method 'sixteen' only (batch fits the bias per sample)");
  if (noise != nullptr) {
    if (noise->gyro_count() != gyros) {
      throw py::value_error("noise: has " + std::to_string(noise->gyro_count()) + " gyros, the log has " +
                            std::to_string(gyros));
    }
    for (const auto& g : noise->gyros) {
      if (!g.noise) throw py::value_error("noise: gyro " + std::to_string(g.id) + " has no 'noise:' section");
      o.noise.push_back(*g.noise);
    }
    o.bias_instability_correlation_s = correlation_s;
  }
  return o;
}

// The latitude given, else the log's "# latitude_deg=" comment.
double latitude_of(const TurntableRows& rows, const std::optional<double>& latitude_deg) {
  if (latitude_deg) return *latitude_deg;
  const auto text = rows.meta("latitude_deg");
  if (!text) {
    throw py::value_error(
        rows.source() +
        ": no latitude: give latitude_deg= or a '# latitude_deg=DEG' comment line in the file");
  }
  const auto v = parse_decimal(*text);
  if (!v)
    raise(bad_input(rows.source() + ": comment '# latitude_deg=" + *text + "' is not a decimal number"));
  return *v;
}

struct Calibrated {
  CalibrationResult result;
  TurntableMotion motion;
};

Calibrated run_calibration(const TurntableRows& rows, const std::optional<double>& latitude_deg,
                           const std::string& method, const std::string& bias_model,
                           const std::optional<std::string>& unit, const Calibration* noise,
                           double correlation_s) {
  CalibrationOptions options =
      calibration_options(method, bias_model, noise, correlation_s, rows.gyro_count());
  const double latitude = latitude_of(rows, latitude_deg);
  options.unit = unit ? *unit : rows.meta("unit").value_or("tetra-1");
  Result<TurntableMotion> motion = bad_input("");
  Result<CalibrationResult> result = bad_input("");
  {
    py::gil_scoped_release release;
    motion = analyze_turntable(rows, latitude);
    if (motion) result = calibrate(rows, *motion, options);
  }
  if (!motion) raise(motion.error());
  if (!result) raise(result.error());
  return Calibrated{std::move(result.value()), std::move(motion.value())};
}

py::array_t<double> matrix(const Eigen::MatrixXd& m) {
  std::vector<double> v(static_cast<std::size_t>(m.size()));
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) v[static_cast<std::size_t>(r * m.cols() + c)] = m(r, c);
  return read_only(std::move(v), static_cast<std::size_t>(m.rows()), static_cast<std::size_t>(m.cols()));
}

py::array_t<double> vector(const Eigen::VectorXd& v) {
  return read_only(std::vector<double>(v.data(), v.data() + v.size()));
}

}  // namespace

static void bind_calibration_class(py::module_& m) {
  py::class_<Calibration>(
      m, "Calibration",
      "A gyro package's calibration (docs/interfaces.md §2.3): per gyro a scale factor "
      "[V/(deg/s)], a bias [V] and a unit sensing axis in the body frame B, with their 1σ "
      "and noise terms when known.")
      .def_static(
          "read", [](const std::filesystem::path& path) { return take(read_calibration(path.string())); },
          "path"_a,
          "Reads a calibration file (YAML; `path` a str or os.PathLike). Raises BadInputError naming the "
          "file, line and key.")
      .def_static(
          "from_yaml",
          [](const std::string& text, const std::string& source) {
            return take(parse_calibration(text, source));
          },
          "text"_a, "source"_a = "<string>", "Parses calibration YAML; `source` names it in messages.")
      .def_static("from_arrays", &calibration_from_arrays, "scale_factor_V_per_dps"_a, "bias_V"_a, "axes_B"_a,
                  "unit"_a = "tetra-1", "method"_a = "python",
                  "A calibration from per-gyro arrays (N scale factors [V/(deg/s)], N biases [V], N×3 unit "
                  "axes in B); validated like a file (N ≥ 3, finite, axes of unit norm within 1e-3).")
      .def_static("seed_unit", &seed_as_built_unit,
                  "The seed paper's unit as built (Tables 4, 5 and 6): the simulator's default unit.")
      .def(
          "to_yaml", [](const Calibration& c) { return format_calibration(c); },
          "The calibration file's text, as `tetra calibrate` writes it (without its provenance comments).")
      .def(
          "write",
          [](const Calibration& c, const std::filesystem::path& path) {
            check(write_calibration(path.string(), c));
          },
          "path"_a,
          "Writes the calibration file (atomically: a temporary file renamed into place); `path` a str or "
          "os.PathLike.")
      .def_readwrite("unit", &Calibration::unit, "Free text naming the unit.")
      .def_readwrite("method", &Calibration::method, "How it was made: 'sixteen-position', 'batch', ...")
      .def_readwrite("latitude_deg", &Calibration::latitude_deg, "[deg] where it was calibrated, or None.")
      .def_property_readonly("gyro_count", &Calibration::gyro_count, "N, the number of gyros.")
      .def_property_readonly(
          "scale_factor_V_per_dps",
          [](const Calibration& c) {
            return per_gyro(c, [](const auto& g) { return g.scale_factor_V_per_dps; });
          },
          "[V/(deg/s)] scale factors, shape (N,): a read-only copy (make a new calibration with "
          "from_arrays).")
      .def_property_readonly(
          "bias_V", [](const Calibration& c) { return per_gyro(c, [](const auto& g) { return g.bias_V; }); },
          "[V] biases, shape (N,).")
      .def_property_readonly(
          "axes_B",
          [](const Calibration& c) { return per_gyro_vec3(c, [](const auto& g) { return g.axis_B; }); },
          "Unit sensing axes in B, shape (N, 3).")
      .def_property_readonly(
          "sigma_scale_factor_V_per_dps",
          [](const Calibration& c) -> py::object {
            if (!all_have_sigma(c)) return py::none();
            return per_gyro(c, [](const auto& g) { return g.sigma->scale_factor_V_per_dps; });
          },
          "[V/(deg/s)] 1σ of the scale factors, shape (N,); None when the file states none.")
      .def_property_readonly(
          "sigma_bias_V",
          [](const Calibration& c) -> py::object {
            if (!all_have_sigma(c)) return py::none();
            return per_gyro(c, [](const auto& g) { return g.sigma->bias_V; });
          },
          "[V] 1σ of the biases, shape (N,); None when the file states none.")
      .def_property_readonly(
          "sigma_axes_B",
          [](const Calibration& c) -> py::object {
            if (!all_have_sigma(c)) return py::none();
            return per_gyro_vec3(c, [](const auto& g) { return g.sigma->axis; });
          },
          "1σ of each axis component, shape (N, 3); None when the file states none.")
      .def_property_readonly(
          "noise",
          [](const Calibration& c) {
            py::list out;
            for (const auto& g : c.gyros) out.append(noise_dict(g.noise));
            return out;
          },
          "Per gyro, its noise terms (dict: quantization_deg, arw_dps_rtHz, bias_instability_dps, "
          "rate_random_walk_dps_per_rts, rate_ramp_dps_per_s; None = not observed), or None.")
      .def("__repr__", [](const Calibration& c) {
        return "<tetra.Calibration unit='" + c.unit + "' method='" + c.method +
               "' gyros=" + std::to_string(c.gyro_count()) + ">";
      });
}

static void bind_calibration_results(py::module_& m) {
  py::class_<Calibrated>(m, "CalibrationResult", "The outcome of tetra.calibrate.")
      .def_property_readonly(
          "calibration", [](Calibrated& r) -> Calibration& { return r.result.calibration; },
          py::return_value_policy::reference_internal,
          "The estimates with their 1σ (a tetra.Calibration): the result's own, not a copy (setting its unit "
          "or method sticks).")
      .def_property_readonly(
          "sequence_residual_V", [](const Calibrated& r) { return matrix(r.result.fit.sequence_residual_V); },
          "[V] M×N mean residual of every gyro over each sequence.")
      .def_property_readonly(
          "sample_rms_V", [](const Calibrated& r) { return vector(r.result.fit.sample_rms_V); },
          "[V] per gyro, RMS of the residual over every sample.")
      .def_property_readonly(
          "sequence_rms_V", [](const Calibrated& r) { return vector(r.result.fit.sequence_rms_V); },
          "[V] per gyro, RMS of the sequence-mean residuals.")
      .def_property_readonly(
          "sequence_sigma_mean_V", [](const Calibrated& r) { return matrix(r.result.sequence_sigma_mean_V); },
          "[V] M×N 1σ of each sequence mean.")
      .def_property_readonly(
          "latitude_deg", [](const Calibrated& r) { return r.motion.latitude_deg; },
          "[deg] the latitude used.")
      .def_property_readonly(
          "sequences", [](const Calibrated& r) { return r.motion.sequences.size(); },
          "The number of sequences of the rotation plan found in the log.");

  m.def(
      "_calibrate_file",
      [](const std::string& path, std::optional<double> latitude_deg, const std::string& method,
         const std::string& bias_model, const std::optional<std::string>& unit, const Calibration* noise,
         double correlation_s) {
        TurntableFileRows rows;
        Status opened = ok_status();
        {
          py::gil_scoped_release release;
          opened = rows.open(path);
        }
        check(opened);
        return run_calibration(rows, latitude_deg, method, bias_model, unit, noise, correlation_s);
      },
      "path"_a, "latitude_deg"_a, "method"_a, "bias_model"_a, "unit"_a, "noise"_a, "correlation_s"_a);
  m.def(
      "_calibrate_arrays",
      [](const py::handle& sequence, const py::handle& time_s, const py::handle& inner_deg,
         const py::handle& outer_deg, const py::handle& g_V, double latitude_deg, const std::string& method,
         const std::string& bias_model, const std::optional<std::string>& unit, const Calibration* noise,
         double correlation_s) {
        const ArrayTurntableRows rows(sequence, time_s, inner_deg, outer_deg, g_V);
        return run_calibration(rows, latitude_deg, method, bias_model, unit, noise, correlation_s);
      },
      "sequence"_a, "time_s"_a, "inner_deg"_a, "outer_deg"_a, "g_V"_a, "latitude_deg"_a, "method"_a,
      "bias_model"_a, "unit"_a, "noise"_a, "correlation_s"_a);
}

void bind_calibration(py::module_& m) {
  bind_calibration_class(m);
  bind_calibration_results(m);
}

}  // namespace tetra::python
