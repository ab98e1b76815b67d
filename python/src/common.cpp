#include "common.hpp"

#include <cmath>
#include <cstring>

namespace tetra::python {

namespace {

PyObject* g_error = nullptr;      // tetra.Error
PyObject* g_bad_input = nullptr;  // tetra.BadInputError

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d > 0 ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string wanted_shape(int cols) {
  if (cols == 0) return "a 1-D array of shape (n,)";
  if (cols < 0) return "a 2-D array of shape (n, columns)";
  return "a 2-D array of shape (n, " + std::to_string(cols) + ")";
}

// A numeric (bool, integer or real) numpy array for `obj`; TypeError otherwise.
py::array numeric_array(const py::handle& obj, const char* name) {
  py::array a = py::array::ensure(obj);
  if (!a) throw py::type_error(std::string(name) + ": expected an array of numbers");
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b') {
    throw py::type_error(std::string(name) + ": expected an array of real numbers, got dtype " +
                         std::string(py::str(a.dtype())));
  }
  return a;
}

}  // namespace

void register_errors(py::module_& m) {
  g_error = PyErr_NewExceptionWithDoc("tetra.Error",
                                      "A tetra library call failed (I/O, internal); the message says why.",
                                      PyExc_RuntimeError, nullptr);
  py::tuple bases = py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError));
  g_bad_input = PyErr_NewExceptionWithDoc(
      "tetra.BadInputError",
      "Bad input (a malformed file, a value out of range): the message names the file, line and key.",
      bases.ptr(), nullptr);
  m.add_object("Error", py::handle(g_error));
  m.add_object("BadInputError", py::handle(g_bad_input));
}

void raise(const Error& error) {
  PyErr_SetString(error.kind == ErrorKind::kBadInput ? g_bad_input : g_error, describe(error).c_str());
  throw py::error_already_set();
}

DoubleArray doubles(const py::handle& obj, const char* name, int cols, Finite finite) {
  py::array a = numeric_array(obj, name);
  const int ndim = cols == 0 ? 1 : 2;
  if (a.ndim() != ndim || (cols > 0 && a.shape(1) != cols)) {
    throw py::value_error(std::string(name) + ": expected " + wanted_shape(cols) + ", got shape " +
                          shape_text(a));
  }
  if (a.shape(0) == 0 || (ndim == 2 && a.shape(1) == 0))
    throw py::value_error(std::string(name) + ": the array is empty");
  DoubleArray out;
  // A view when the caller's array is already C-contiguous float64: array_t's cast then returns it as is.
  out.holder = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  auto view = py::array_t<double, py::array::c_style>::ensure(out.holder);
  out.data = view.data();
  out.rows = static_cast<std::size_t>(a.shape(0));
  out.cols = ndim == 2 ? static_cast<std::size_t>(a.shape(1)) : 1;
  if (finite == Finite::kRequired) {
    const std::size_t n = out.rows * out.cols;
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(out.data[i])) {
        const std::string where =
            ndim == 1 ? "[" + std::to_string(i) + "]"
                      : "[" + std::to_string(i / out.cols) + ", " + std::to_string(i % out.cols) + "]";
        throw py::value_error(std::string(name) + where + ": " +
                              (std::isnan(out.data[i]) ? "NaN" : "infinite") +
                              " where a finite number is required");
      }
    }
  }
  return out;
}

MaskArray mask(const py::handle& obj, const char* name, std::size_t rows, std::size_t cols) {
  py::array a = numeric_array(obj, name);
  const int ndim = cols == 0 ? 1 : 2;
  const bool shape_ok = a.ndim() == ndim && static_cast<std::size_t>(a.shape(0)) == rows &&
                        (ndim == 1 || static_cast<std::size_t>(a.shape(1)) == cols);
  if (!shape_ok) {
    throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(rows) +
                          (ndim == 1 ? ",)" : ", " + std::to_string(cols) + ")") + " like the samples, got " +
                          shape_text(a));
  }
  MaskArray out;
  const char kind = a.dtype().kind();
  const bool byte_sized = (kind == 'b' || kind == 'u') && a.itemsize() == 1;
  if (byte_sized && (a.flags() & py::array::c_style) != 0) {
    out.holder = a;  // bool and uint8: one byte, read in place (the library takes any nonzero as present)
  } else {
    // Nonzero is present: a cast to uint8 would wrap (256 -> 0) or truncate (0.5 -> 0).
    out.holder = a.attr("astype")(py::dtype("bool"), py::arg("order") = "C");
  }
  out.data = static_cast<const std::uint8_t*>(out.holder.data());
  return out;
}

}  // namespace tetra::python
