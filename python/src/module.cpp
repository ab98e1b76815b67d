// The Python module tetra._tetra (the package tetra wraps it; docs/python.md).
#include "common.hpp"

PYBIND11_MODULE(_tetra, m) {
  m.doc() = "tetra's libraries (core, fdi, sim) from Python: the package `tetra` wraps this module.";
  m.attr("__version__") = TETRA_VERSION;
  tetra::python::register_errors(m);
  tetra::python::bind_calibration(m);
  tetra::python::bind_logs(m);
  tetra::python::bind_allan(m);
  tetra::python::bind_sim(m);
  tetra::python::bind_pipeline(m);
  tetra::python::bind_score(m);
  tetra::python::bind_campaign(m);
#ifdef TETRA_WITH_DDS
  tetra::python::bind_dds(m);
#else
  m.attr("_HAS_DDS") = false;
#endif
}
