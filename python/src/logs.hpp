#pragma once
// tetra.GyroLog: a gyro log (docs/interfaces.md §2.2) as numpy arrays.
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "tetra/core/gyro_log.hpp"

namespace tetra::python {

struct PyGyroLog {
  std::string source;
  std::vector<std::pair<std::string, std::string>> metadata;
  int gyro_count = 0;
  bool units_dps = false;
  py::array_t<double> time_s;         //!< [s] (n,)
  py::array_t<double> values;         //!< [V or deg/s] (n, N)
  py::array_t<std::uint8_t> present;  //!< (n, N)
  py::object reference_wxyz;          //!< (n, 4) NaN where none, or None
  py::object reference_present;       //!< (n,) uint8, or None
};

//! The log's vectors handed over to numpy (no copy).
PyGyroLog to_python(GyroLog&& log);

}  // namespace tetra::python
