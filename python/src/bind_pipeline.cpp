// tetra.Pipeline: the fusion and fault-detection pipeline, one epoch at a time (step) or a whole array of
// epochs in C++ (run: no Python per epoch, the GIL released).
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "common.hpp"
#include "events.hpp"
#include "logs.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/noise_defaults.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "watch.hpp"

namespace tetra::python {

namespace {

using namespace pybind11::literals;

// The attitude estimates of a run, one row per accepted epoch, in the units and with the arithmetic of
// `tetra replay --attitude` (attitude_csv), so the numbers equal that file's to the last bit.
struct RunColumns {
  std::vector<double> time_s, q, omega_dps, sigma_deg, sigma_B_deg, bias_dps, pl_deg;
  std::vector<std::uint8_t> mode, fdi_available;
  std::vector<std::uint32_t> gyros;
  std::vector<fdi::FdiEvent> events;
  std::size_t epochs = 0;

  void reserve(std::size_t n, std::size_t ng) {
    time_s.reserve(n);
    q.reserve(4 * n);
    omega_dps.reserve(3 * n);
    sigma_deg.reserve(n);
    sigma_B_deg.reserve(3 * n);
    bias_dps.reserve(ng * n);
    pl_deg.reserve(3 * n);
    mode.reserve(n);
    fdi_available.reserve(n);
    gyros.reserve(n);
  }
  void add(double t_s, const fdi::AttitudeEstimate& a, std::size_t ng) {
    time_s.push_back(t_s);
    for (const double c : to_wxyz(a.q_RB)) q.push_back(c);
    for (int i = 0; i < 3; ++i) omega_dps.push_back(a.omega_BR_B_rad_s[i] * kRadToDeg);
    sigma_deg.push_back(a.sigma_rad.norm() * kRadToDeg);
    for (int i = 0; i < 3; ++i) sigma_B_deg.push_back(a.sigma_rad[i] * kRadToDeg);
    const bool biases = a.gyro_bias_rad_s.size() == ng;
    for (std::size_t i = 0; i < ng; ++i)
      bias_dps.push_back(biases ? a.gyro_bias_rad_s[i] * kRadToDeg
                                : std::numeric_limits<double>::quiet_NaN());
    for (int i = 0; i < 3; ++i) pl_deg.push_back(a.protection_level_rad[i] * kRadToDeg);
    mode.push_back(static_cast<std::uint8_t>(a.mode));
    fdi_available.push_back(a.fdi_available ? 1 : 0);
    gyros.push_back(a.gyros);
  }
};

struct PyPipeline {
  PyPipeline(fdi::Pipeline p, fdi::PipelineConfig c, int gyros)
      : pipeline(std::move(p)), config(std::move(c)), n(gyros) {
    epoch.raw.resize(static_cast<std::size_t>(n));
    epoch.present.resize(static_cast<std::size_t>(n));
  }
  fdi::Pipeline pipeline;
  const fdi::PipelineConfig config;
  const int n;
  fdi::Epoch epoch;
  std::atomic<const char*> user{nullptr};  //!< the method running on it (InUse), or null
};

// One method call's hold on a Pipeline. A second call while one runs — from another thread, or from the
// progress callback of a run — raises RuntimeError instead of sharing the pipeline's state: a mutex would
// interleave two threads' epochs into one filter (an estimate of neither), and with the GIL taken back by
// the run's polls it could deadlock.
class InUse {
 public:
  InUse(PyPipeline& p, const char* method) : p_(p) {
    const char* idle = nullptr;
    if (!p_.user.compare_exchange_strong(idle, method)) {
      throw std::runtime_error(std::string("tetra.Pipeline is in use: ") + idle +
                               " is running on it (in another "
                               "thread, or this call came from its progress callback); a Pipeline serves one "
                               "call at a time: give each thread its own Pipeline, or hold a threading.Lock "
                               "around its calls");
    }
  }
  InUse(const InUse&) = delete;
  InUse& operator=(const InUse&) = delete;
  ~InUse() { p_.user.store(nullptr); }

 private:
  PyPipeline& p_;
};

// The inputs of run(): checked, as views of the caller's arrays where they can be.
struct RunInputs {
  DoubleArray time_s, raw, reference;
  MaskArray present, reference_present;
  bool has_reference = false;
};

RunInputs run_inputs(const py::handle& time_s, const py::handle& raw, const py::object& present,
                     const py::object& reference_wxyz, const py::object& reference_present, int n) {
  RunInputs in;
  in.time_s = doubles(time_s, "time_s", 0, Finite::kRequired);
  for (std::size_t k = 0; k < in.time_s.rows; ++k) {
    if (const auto problem = log_time_problem(in.time_s.data[k]))
      throw py::value_error("time_s[" + std::to_string(k) + "]: " + *problem);
  }
  in.raw = doubles(raw, "raw", n, Finite::kNanAllowed);
  const std::size_t rows = in.time_s.rows;
  if (in.raw.rows != rows) {
    throw py::value_error("raw: expected one row per time_s (" + std::to_string(rows) + "), got " +
                          std::to_string(in.raw.rows));
  }
  if (!present.is_none()) in.present = mask(present, "present", rows, static_cast<std::size_t>(n));
  if (!reference_wxyz.is_none()) {
    in.reference = doubles(reference_wxyz, "reference_wxyz", 4, Finite::kNanAllowed);
    if (in.reference.rows != rows) {
      throw py::value_error("reference_wxyz: expected one row per time_s (" + std::to_string(rows) +
                            "), got " + std::to_string(in.reference.rows));
    }
    in.has_reference = true;
    if (!reference_present.is_none())
      in.reference_present = mask(reference_present, "reference_present", rows, 0);
  } else if (!reference_present.is_none()) {
    throw py::value_error("reference_present: given without reference_wxyz");
  }
  return in;
}

// Epoch k of the inputs into `epoch` (as tetra replay builds it from a log row).
void fill_epoch(const RunInputs& in, std::size_t k, std::size_t ng, fdi::Epoch& epoch) {
  epoch.stamp_ns = seconds_to_ns(in.time_s.data[k]);
  const double* row = in.raw.data + k * ng;
  for (std::size_t i = 0; i < ng; ++i) {
    epoch.raw[i] = row[i];
    epoch.present[i] = in.present.data == nullptr || in.present.data[k * ng + i] != 0 ? 1 : 0;
  }
  epoch.reference_q_RB.reset();
  if (!in.has_reference) return;
  const double* q = in.reference.data + 4 * k;
  const bool given = in.reference_present.data != nullptr
                         ? in.reference_present.data[k] != 0
                         : !(std::isnan(q[0]) || std::isnan(q[1]) || std::isnan(q[2]) || std::isnan(q[3]));
  if (given) epoch.reference_q_RB = from_wxyz(q[0], q[1], q[2], q[3]);
}

// Every epoch, or those before `interrupt` (polled every 64 epochs) asked to stop.
RunColumns run_all(PyPipeline& p, const RunInputs& in, Interrupt& interrupt) {
  const auto ng = static_cast<std::size_t>(p.n);
  RunColumns out;
  out.reserve(in.time_s.rows, ng);
  for (std::size_t k = 0; k < in.time_s.rows; ++k) {
    if (k % 64 == 0 && interrupt.requested(k, in.time_s.rows)) {
      out.epochs = k;
      return out;
    }
    fill_epoch(in, k, ng, p.epoch);
    const auto& r = p.pipeline.step(p.epoch);
    out.events.insert(out.events.end(), r.events.begin(), r.events.end());
    if (r.accepted) out.add(in.time_s.data[k], r.attitude, ng);
  }
  out.epochs = in.time_s.rows;
  return out;
}

py::dict run_result(RunColumns&& c, int n) {
  const std::size_t m = c.time_s.size();
  py::dict d;
  d["epochs"] = c.epochs;
  d["time_s"] = to_numpy(std::move(c.time_s));
  d["q_RB_wxyz"] = to_numpy(std::move(c.q), m, 4);
  d["omega_BR_B_dps"] = to_numpy(std::move(c.omega_dps), m, 3);
  d["sigma_deg"] = to_numpy(std::move(c.sigma_deg));
  d["sigma_B_deg"] = to_numpy(std::move(c.sigma_B_deg), m, 3);
  d["bias_dps"] = to_numpy(std::move(c.bias_dps), m, static_cast<std::size_t>(n));
  d["protection_level_B_deg"] = to_numpy(std::move(c.pl_deg), m, 3);
  d["mode"] = to_numpy(std::move(c.mode));
  d["fdi_available"] = to_numpy(std::move(c.fdi_available));
  d["gyros"] = to_numpy(std::move(c.gyros));
  py::list events;
  for (const auto& e : c.events) events.append(event_dict(e, n));
  d["events"] = events;
  return d;
}

py::dict attitude_dict(const fdi::AttitudeEstimate& a, int n) {
  RunColumns one;
  one.add(static_cast<double>(a.stamp_ns) * 1e-9, a, static_cast<std::size_t>(n));
  py::dict d;
  d["stamp_ns"] = a.stamp_ns;
  d["q_RB_wxyz"] = to_numpy(std::move(one.q));
  d["omega_BR_B_dps"] = to_numpy(std::move(one.omega_dps));
  d["sigma_deg"] = one.sigma_deg[0];
  d["sigma_B_deg"] = to_numpy(std::move(one.sigma_B_deg));
  d["bias_dps"] = to_numpy(std::move(one.bias_dps));
  d["protection_level_B_deg"] = to_numpy(std::move(one.pl_deg));
  d["mode"] = fdi::to_string(a.mode);
  d["gyros"] = gyro_ids(a.gyros, n);
  d["fdi_available"] = a.fdi_available;
  return d;
}

py::dict health_dict(const fdi::Health& h, int n) {
  py::dict d = health_state_dict(h, n);
  const auto& c = h.counters;
  d["counters"] = py::dict(
      "epochs_accepted"_a = c.epochs_accepted, "epochs_rejected_time"_a = c.epochs_rejected_time,
      "epochs_time_outlier"_a = c.epochs_time_outlier, "epochs_rejected_shape"_a = c.epochs_rejected_shape,
      "samples_accepted"_a = c.samples_accepted, "samples_invalid"_a = c.samples_invalid,
      "samples_absent"_a = c.samples_absent, "samples_outlier"_a = c.samples_outlier, "spikes"_a = c.spikes,
      "reference_accepted"_a = c.reference_accepted, "reference_rejected"_a = c.reference_rejected,
      "reference_reinitialized"_a = c.reference_reinitialized, "reference_invalid"_a = c.reference_invalid,
      "reference_delayed"_a = c.reference_delayed, "reference_too_late"_a = c.reference_too_late);
  return d;
}

}  // namespace

static void bind_pipeline_config(py::module_& m) {
  py::class_<fdi::PipelineConfig>(m, "PipelineConfig",
                                  "The pipeline's configuration (the `pipeline:` map, docs/fdi.md).")
      .def(py::init<>(), "Every key at its default.")
      .def(
          "describe", [](const fdi::PipelineConfig& c) { return fdi::describe(c); },
          "Every key and its value, one 'key: value' line each.")
      .def_readwrite("latitude_deg", &fdi::PipelineConfig::latitude_deg,
                     "[deg] ground-test mode (the Earth rate removed), or None.")
      .def_readwrite("raw_units_dps", &fdi::PipelineConfig::raw_units_dps, "Samples are rates [deg/s].");
  m.def(
      "_parse_pipeline_config",
      [](const std::string& text, const std::string& source) {
        return take(fdi::parse_pipeline_config(text, source));
      },
      "text"_a, "source"_a);
  m.def(
      "_read_pipeline_config", [](const std::string& path) { return take(fdi::read_pipeline_config(path)); },
      "path"_a);
}

//! The class, its constructor and what it tells of itself.
static py::class_<PyPipeline> bind_pipeline_basics(py::module_& m) {
  py::class_<PyPipeline> c(m, "_Pipeline");
  c.def(py::init([](const Calibration& calibration, fdi::PipelineConfig config, bool units_dps) {
          config.raw_units_dps = units_dps;
          check(fdi::validate(config));
          auto p = take(fdi::Pipeline::create(calibration, config));
          return std::make_unique<PyPipeline>(std::move(p), config, calibration.gyro_count());
        }),
        "calibration"_a, "config"_a, "units_dps"_a)
      .def_property_readonly("gyro_count", [](const PyPipeline& p) { return p.n; })
      .def_property_readonly("config", [](const PyPipeline& p) { return p.config; })
      .def("describe_thresholds",
           [](PyPipeline& p) {
             const InUse in_use(p, "Pipeline.describe_thresholds");
             return p.pipeline.describe_thresholds();
           })
      .def(
          "default_noise_warning",
          [](const PyPipeline& p, const Calibration& cal) {
            return fdi::default_noise_warning(cal, p.config);
          },
          "calibration"_a);
  return c;
}

//! The operator commands and the state they reset or read.
static void bind_pipeline_commands(py::class_<PyPipeline>& c) {
  c.def("reset",
        [](PyPipeline& p) {
          const InUse in_use(p, "Pipeline.reset");
          p.pipeline.reset();
        })
      .def("health",
           [](PyPipeline& p) {
             const InUse in_use(p, "Pipeline.health");
             return health_dict(p.pipeline.health(), p.n);
           })
      .def(
          "exclude",
          [](PyPipeline& p, int gyro, std::int64_t stamp_ns, bool force) {
            const InUse in_use(p, "Pipeline.exclude");
            return event_dict(p.pipeline.exclude(gyro, stamp_ns, force), p.n);
          },
          "gyro"_a, "stamp_ns"_a, "force"_a)
      .def(
          "reinstate",
          [](PyPipeline& p, int gyro, std::int64_t stamp_ns) {
            const InUse in_use(p, "Pipeline.reinstate");
            return event_dict(p.pipeline.reinstate(gyro, stamp_ns), p.n);
          },
          "gyro"_a, "stamp_ns"_a)
      .def(
          "reset_command",
          [](PyPipeline& p, std::int64_t stamp_ns) {
            const InUse in_use(p, "Pipeline.reset_command");
            return event_dict(p.pipeline.reset_command(stamp_ns), p.n);
          },
          "stamp_ns"_a);
}

//! One epoch at a time, or a whole log.
static void bind_pipeline_stepping(py::class_<PyPipeline>& c) {
  c.def(
       "step",
       [](PyPipeline& p, const py::handle& time_s, const py::handle& raw, const py::object& present,
          const py::object& reference_wxyz) {
         const InUse in_use(p, "Pipeline.step");
         const RunInputs in = run_inputs(time_s, raw, present, reference_wxyz, py::none(), p.n);
         if (in.time_s.rows != 1) throw py::value_error("time_s: step takes one epoch");
         fill_epoch(in, 0, static_cast<std::size_t>(p.n), p.epoch);
         const auto& r = p.pipeline.step(p.epoch);
         py::dict d;
         d["accepted"] = r.accepted;
         d["attitude"] = r.accepted ? py::object(attitude_dict(r.attitude, p.n)) : py::object(py::none());
         py::list events;
         for (const auto& e : r.events) events.append(event_dict(e, p.n));
         d["events"] = events;
         return d;
       },
       "time_s"_a, "raw"_a, "present"_a, "reference_wxyz"_a)
      .def(
          "run",
          [](PyPipeline& p, const py::handle& time_s, const py::handle& raw, const py::object& present,
             const py::object& reference_wxyz, const py::object& reference_present,
             const py::object& progress) {
            const InUse in_use(p, "Pipeline.run");
            const RunInputs in = run_inputs(time_s, raw, present, reference_wxyz, reference_present, p.n);
            Watch watch(progress);
            Interrupt interrupt = watch.interrupt();
            RunColumns columns;
            {
              py::gil_scoped_release release;
              columns = run_all(p, in, interrupt);
            }
            watch.raise_if_stopped();  // the rows so far are freed with `columns`
            watch.done(columns.epochs, in.time_s.rows);
            return run_result(std::move(columns), p.n);
          },
          "time_s"_a, "raw"_a, "present"_a, "reference_wxyz"_a, "reference_present"_a, "progress"_a);
}

//! The module's constants and helpers of the class.
static void bind_pipeline_helpers(py::module_& m) {
  m.attr("MODE_NAMES") =
      py::make_tuple(fdi::to_string(fdi::Mode::kNominal), fdi::to_string(fdi::Mode::kDegraded),
                     fdi::to_string(fdi::Mode::kSuspect), fdi::to_string(fdi::Mode::kLost));
  m.def(
      "_is_view",
      [](const py::handle& array) {
        py::array a = py::array::ensure(array);
        const DoubleArray d = doubles(a, "array", a.ndim() == 1 ? 0 : -1, Finite::kNanAllowed);
        return d.data == a.data();
      },
      "array"_a, "True when tetra reads `array` in place (C-contiguous float64), False when it copies it.");
}

static void bind_pipeline_class(py::module_& m) {
  py::class_<PyPipeline> c = bind_pipeline_basics(m);
  bind_pipeline_commands(c);
  bind_pipeline_stepping(c);
  bind_pipeline_helpers(m);
}

void bind_pipeline(py::module_& m) {
  bind_pipeline_config(m);
  bind_pipeline_class(m);
}

}  // namespace tetra::python
