// tetra.sim (a scenario → its gyro log and truth as numpy arrays), scenarios, and the turntable plan.
#include <optional>
#include <string>

#include <pybind11/stl.h>

#include "common.hpp"
#include "logs.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"
#include "tetra/sim/turntable.hpp"
#include "watch.hpp"

namespace tetra::python {

namespace {

using namespace pybind11::literals;

struct PyTruth {
  py::array_t<double> time_s;            //!< [s] (n,)
  py::array_t<double> q_RB_wxyz;         //!< body → reference (n, 4)
  py::array_t<double> omega_BR_B_rad_s;  //!< [rad/s] (n, 3)
  py::array_t<double> omega_BN_B_rad_s;  //!< [rad/s] (n, 3)
};

struct SimRun {
  PyGyroLog log;
  PyTruth truth;
};

PyTruth to_python(sim::Truth&& t) {
  const std::size_t n = t.time_s.size();
  std::vector<double> q(4 * n), w(3 * n), wn(3 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto wxyz = to_wxyz(canonical(t.q_RB[k]));  // as the truth file: normalized, w >= 0
    for (std::size_t c = 0; c < 4; ++c) q[4 * k + c] = wxyz[c] + 0.0;  // + 0.0: no -0, as the file
    for (std::size_t a = 0; a < 3; ++a) {
      w[3 * k + a] = t.omega_BR_B_rad_s[k][static_cast<Eigen::Index>(a)];
      wn[3 * k + a] = t.omega_BN_B_rad_s[k][static_cast<Eigen::Index>(a)];
    }
  }
  PyTruth out;
  out.time_s = to_numpy(std::move(t.time_s));
  out.q_RB_wxyz = to_numpy(std::move(q), n, 4);
  out.omega_BR_B_rad_s = to_numpy(std::move(w), n, 3);
  out.omega_BN_B_rad_s = to_numpy(std::move(wn), n, 3);
  return out;
}

}  // namespace

static void bind_scenarios(py::module_& m) {
  py::class_<sim::Scenario>(m, "Scenario",
                            "What is simulated (docs/sim.md): motion, duration, sampling, unit, reference, "
                            "faults. Made by tetra.scenario from a built-in name, a file or a dict.")
      .def_readwrite("name", &sim::Scenario::name, "Built-in name or file name.")
      .def_readwrite("duration_s", &sim::Scenario::duration_s, "[s] length of the run.")
      .def_readwrite("rate_hz", &sim::Scenario::rate_hz, "[Hz] gyro sampling rate.")
      .def_readwrite("unit", &sim::Scenario::unit,
                     "The simulated unit's as-built truth (a tetra.Calibration).")
      .def_property_readonly(
          "closed_loop", [](const sim::Scenario& s) { return s.closed_loop.has_value(); },
          "True when the scenario has a closed_loop section (campaigns only).")
      .def("__repr__", [](const sim::Scenario& s) {
        return "<tetra.Scenario '" + s.name + "' " + std::to_string(s.duration_s) + " s at " +
               std::to_string(s.rate_hz) + " Hz>";
      });
  m.def("builtin_scenarios", &sim::builtin_scenario_names, "Names of the built-in scenarios.");
  m.def(
      "_builtin_scenario", [](const std::string& name) { return take(sim::builtin_scenario(name)); },
      "name"_a);
  m.def(
      "_read_scenario", [](const std::string& path) { return take(sim::read_scenario(path)); }, "path"_a);
  m.def(
      "_parse_scenario",
      [](const std::string& text, const std::string& source, const std::string& base_dir) {
        return take(sim::parse_scenario(text, source, base_dir));
      },
      "text"_a, "source"_a, "base_dir"_a);
}

static void bind_sim_runs(py::module_& m) {
  py::class_<PyTruth>(m, "Truth", "The simulated truth, one row per epoch.")
      .def_readonly("time_s", &PyTruth::time_s, "[s] (n,)")
      .def_readonly("q_RB_wxyz", &PyTruth::q_RB_wxyz,
                    "True attitude body → reference (w, x, y, z), (n, 4), as `tetra sim --truth` writes it: "
                    "normalized, w ≥ 0.")
      .def_readonly("omega_BR_B_rad_s", &PyTruth::omega_BR_B_rad_s,
                    "[rad/s] rate of B relative to R, in B, (n, 3).")
      .def_readonly("omega_BN_B_rad_s", &PyTruth::omega_BN_B_rad_s,
                    "[rad/s] inertial rate of B, in B, (n, 3).");
  py::class_<SimRun>(m, "SimRun", "A simulated run: the gyro log and the truth.")
      .def_readonly("log", &SimRun::log, "The gyro log (a tetra.GyroLog, volts).")
      .def_readonly("truth", &SimRun::truth, "The truth (a tetra.Truth).");
  m.def(
      "_simulate",
      // The scenario by value: a copy no other thread can change while the GIL is released.
      [](sim::Scenario scenario, std::uint64_t seed, const py::object& progress) {
        sim::SimOptions options;
        options.seed = seed;
        sim::Truth truth;
        Watch watch(progress);
        Interrupt interrupt = watch.interrupt();
        Result<GyroLog> log = bad_input("");
        {
          py::gil_scoped_release release;
          log = sim::simulate_log(scenario, options, &truth, &interrupt);
        }
        watch.raise_if_stopped();
        SimRun run;
        run.log = to_python(take(std::move(log)));
        run.truth = to_python(std::move(truth));
        watch.done(run.truth.time_s.size(), run.truth.time_s.size());
        return run;
      },
      "scenario"_a, "seed"_a, "progress"_a);

  m.def(
      "_simulate_turntable",
      [](const Calibration& unit, double table_rate_dps, double revolutions, double rate_hz,
         double latitude_deg, std::uint64_t seed) {
        sim::TurntablePlan plan;
        plan.table_rate_dps = table_rate_dps;
        plan.revolutions = revolutions;
        plan.rate_hz = rate_hz;
        plan.latitude_deg = latitude_deg;
        Result<TurntableLog> log = bad_input("");
        {
          py::gil_scoped_release release;
          log = sim::simulate_turntable(unit, plan, seed);
        }
        TurntableLog t = take(std::move(log));
        const std::size_t n = t.rows();
        std::string text = format_turntable_log(t);
        std::vector<std::int64_t> sequence(t.sequence.begin(), t.sequence.end());
        py::dict d;
        d["sequence"] = to_numpy(std::move(sequence));
        d["time_s"] = to_numpy(std::move(t.time_s));
        d["inner_deg"] = to_numpy(std::move(t.inner_deg));
        d["outer_deg"] = to_numpy(std::move(t.outer_deg));
        d["g_V"] = to_numpy(std::move(t.g_V), n, static_cast<std::size_t>(t.gyro_count));
        d["metadata"] = t.metadata;
        d["text"] = std::move(text);
        return d;
      },
      "unit"_a, "table_rate_dps"_a, "revolutions"_a, "rate_hz"_a, "latitude_deg"_a, "seed"_a);
}

void bind_sim(py::module_& m) {
  bind_scenarios(m);
  bind_sim_runs(m);
}

}  // namespace tetra::python
