#pragma once
// Shared by the bindings of the Python module tetra._tetra: library errors as Python exceptions, and
// numpy arrays in (checked views) and out (vectors handed over without a copy).
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "tetra/core/result.hpp"

namespace tetra::python {

namespace py = pybind11;

//! Creates tetra.Error (RuntimeError) and tetra.BadInputError (tetra.Error and ValueError) in `m`.
void register_errors(py::module_& m);
//! Raises the library's error as tetra.BadInputError (kBadInput) or tetra.Error, with its whole message.
[[noreturn]] void raise(const Error& error);
inline void check(const Status& status) {
  if (!status) raise(status.error());
}
template <class T>
T take(Result<T>&& result) {
  if (!result) raise(result.error());
  return std::move(result).value();
}

//! A read-only float64 array: a view of the caller's array when it is C-contiguous float64 (no copy),
//! otherwise one converted copy (other real dtypes, strided views). `holder` keeps it alive.
struct DoubleArray {
  py::array holder;
  const double* data = nullptr;
  std::size_t rows = 0;  //!< first dimension (the length of a 1-D array)
  std::size_t cols = 1;  //!< second dimension (1 for a 1-D array)
  double operator()(std::size_t r, std::size_t c) const { return data[r * cols + c]; }
};
//! What a DoubleArray's values may be.
enum class Finite { kRequired, kNanAllowed };
//! `obj` as a 1-D (`cols` == 0) or 2-D array of `cols` columns (`cols` < 0: any number). Raises TypeError
//! for a non-numeric dtype and ValueError naming `name` for a wrong shape, an empty array or (kRequired) a
//! NaN or infinite value.
DoubleArray doubles(const py::handle& obj, const char* name, int cols, Finite finite);
//! A 0/1 mask (bool or any integer dtype) shaped rows × cols (cols 0: 1-D): a view of a C-contiguous bool
//! or uint8 array, otherwise a converted copy.
struct MaskArray {
  py::array holder;
  const std::uint8_t* data = nullptr;
};
MaskArray mask(const py::handle& obj, const char* name, std::size_t rows, std::size_t cols);

//! Hands `values` over to numpy without a copy (the array owns the vector), shaped rows × cols (cols 0:
//! 1-D).
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& values, std::size_t rows, std::size_t cols = 0) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  if (cols == 0) {
    return py::array_t<T>({static_cast<py::ssize_t>(rows)}, owned->data(), free_when_done);
  }
  return py::array_t<T>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)}, owned->data(),
                        free_when_done);
}
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& values) {
  const std::size_t n = values.size();
  return to_numpy(std::move(values), n);
}

//! `a` made read-only: for arrays a property computes afresh at each access (a copy of the object's
//! values), so that assigning into one raises instead of changing nothing.
template <class T>
py::array_t<T> read_only(py::array_t<T> a) {
  a.attr("setflags")(py::arg("write") = false);
  return a;
}
//! The same for a vector handed over (to_numpy's shapes).
template <class T>
py::array_t<T> read_only(std::vector<T>&& values, std::size_t rows, std::size_t cols = 0) {
  return read_only(to_numpy(std::move(values), rows, cols));
}
template <class T>
py::array_t<T> read_only(std::vector<T>&& values) {
  return read_only(to_numpy(std::move(values)));
}

//! The bindings, one function per file.
void bind_calibration(py::module_& m);
void bind_logs(py::module_& m);
void bind_allan(py::module_& m);
void bind_sim(py::module_& m);
void bind_pipeline(py::module_& m);
void bind_score(py::module_& m);
void bind_campaign(py::module_& m);
void bind_dds(py::module_& m);  //!< with TETRA_WITH_DDS only

}  // namespace tetra::python
