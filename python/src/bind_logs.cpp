// tetra.GyroLog and tetra.read_gyro_log.
#include <filesystem>
#include <limits>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "common.hpp"
#include "logs.hpp"

namespace tetra::python {

using namespace pybind11::literals;

PyGyroLog to_python(GyroLog&& log) {
  PyGyroLog out;
  const std::size_t n = log.epochs();
  const auto ng = static_cast<std::size_t>(log.gyro_count);
  out.source = std::move(log.source);
  out.metadata = std::move(log.metadata);
  out.gyro_count = log.gyro_count;
  out.units_dps = log.units_dps;
  out.time_s = to_numpy(std::move(log.time_s));
  out.values = to_numpy(std::move(log.values), n, ng);
  out.present = to_numpy(std::move(log.present), n, ng);
  out.reference_wxyz = py::none();
  out.reference_present = py::none();
  if (log.has_reference) {
    std::vector<double> q(4 * n, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t k = 0; k < n; ++k) {
      if (log.reference_present[k] == 0) continue;
      for (std::size_t c = 0; c < 4; ++c) q[4 * k + c] = log.reference_wxyz[k][c];
    }
    out.reference_wxyz = to_numpy(std::move(q), n, 4);
    out.reference_present = to_numpy(std::move(log.reference_present));
  }
  return out;
}

void bind_logs(py::module_& m) {
  py::class_<PyGyroLog>(
      m, "GyroLog",
      "A gyro log (docs/interfaces.md §2.2) as numpy arrays: what tetra.read_gyro_log reads "
      "and tetra.sim makes, and what Pipeline.run_log replays.")
      .def_readonly("source", &PyGyroLog::source, "File name (or what made the log).")
      .def_readonly("metadata", &PyGyroLog::metadata, "The '# key=value' comment lines, in order.")
      .def_readonly("gyro_count", &PyGyroLog::gyro_count, "N, the gyro columns g1..gN.")
      .def_readonly("units_dps", &PyGyroLog::units_dps, "True: values are rates [deg/s]; False: volts.")
      .def_readonly("time_s", &PyGyroLog::time_s, "[s] epoch times, shape (n,).")
      .def_readonly("values", &PyGyroLog::values,
                    "[V or deg/s] samples, shape (n, N); NaN where absent or invalid.")
      .def_readonly("present", &PyGyroLog::present, "uint8 (n, N): 0 where no sample was delivered.")
      .def_readonly("reference_wxyz", &PyGyroLog::reference_wxyz,
                    "Attitude reference body → reference (w, x, y, z), shape (n, 4), NaN on epochs without "
                    "one; None when the log has no reference columns.")
      .def_readonly("reference_present", &PyGyroLog::reference_present,
                    "uint8 (n,): 1 where the epoch carries a reference; None without reference columns.")
      .def("__len__", [](const PyGyroLog& l) { return l.time_s.size(); })
      .def("__repr__", [](const PyGyroLog& l) {
        return "<tetra.GyroLog '" + l.source + "' epochs=" + std::to_string(l.time_s.size()) +
               " gyros=" + std::to_string(l.gyro_count) + (l.units_dps ? " deg/s" : " V") + ">";
      });
  m.def(
      "read_gyro_log",
      [](const std::filesystem::path& path) {
        const std::string name = path.string();
        Result<GyroLog> log = bad_input("");
        {
          py::gil_scoped_release release;
          log = read_gyro_log(name);
        }
        return to_python(take(std::move(log)));
      },
      "path"_a,
      "Reads a whole gyro log: CSV, HDF5 (.h5, .hdf5) or the lab's TDMS (.tdms; docs/formats.md). `path` "
      "a str or os.PathLike. Raises BadInputError naming file and line.");
}

}  // namespace tetra::python
