// Attributes of the HDF5 gyro log (gyro_log_h5_internal.hpp): written as fixed-length strings, read
// with bounded, checked types.
#include <algorithm>
#include <cstring>

#include "gyro_log_h5_internal.hpp"

namespace tetra::h5io {

// --- attributes ---------------------------------------------------------------------------------

// Fixed-length UTF-8 strings of `size` bytes each (NUL-padded): stored in the attribute itself, so a
// reader needs no global heap (variable-length strings live there; see read_string_attribute).
namespace {
Handle fixed_string_type(std::size_t size) {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), std::max<std::size_t>(size, 1));
  H5Tset_strpad(t.get(), H5T_STR_NULLPAD);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

}  // namespace

bool write_string_attribute(hid_t obj, const char* name, const std::vector<std::string>& values,
                            bool scalar) {
  std::size_t size = 1;
  for (const std::string& v : values) size = std::max(size, v.size());
  Handle type = fixed_string_type(size);
  const hsize_t n = values.size();
  Handle space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
  Handle attr(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) return false;
  std::vector<char> buf(values.size() * size, '\0');
  for (std::size_t i = 0; i < values.size(); ++i)
    std::memcpy(buf.data() + i * size, values[i].data(), values[i].size());
  return H5Awrite(attr.get(), type.get(), buf.data()) >= 0;
}

bool write_int_attribute(hid_t obj, const char* name, int value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name, H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  return attr.valid() && H5Awrite(attr.get(), H5T_NATIVE_INT, &value) >= 0;
}

// Strings of a string attribute (scalar or 1-D; fixed or variable length): nullopt when absent, an
// error when it is not strings or larger than kMaxAttributeBytes.
Result<std::optional<std::vector<std::string>>> read_string_attribute(hid_t obj, const char* name,
                                                                      const std::string& src,
                                                                      VariableStrings vlen) {
  using Strings = std::optional<std::vector<std::string>>;
  if (H5Aexists(obj, name) <= 0) return Strings{};
  const std::string what = src + ": attribute '" + name + "'";
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  Handle ftype(H5Aget_type(attr.get()), H5Tclose);
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  if (!attr.valid() || !ftype.valid() || !space.valid())
    return bad_input(what + " cannot be read (damaged file?)");
  if (H5Tget_class(ftype.get()) != H5T_STRING) return bad_input(what + " is not text");
  const hssize_t count = H5Sget_simple_extent_npoints(space.get());
  if (count < 0 || H5Sget_simple_extent_ndims(space.get()) > 1 ||
      static_cast<std::size_t>(count) > kMaxAttributeBytes / 8) {
    return bad_input(what + " is not a list of strings of bounded size");
  }
  const auto n = static_cast<std::size_t>(count);
  std::vector<std::string> out;
  if (H5Tis_variable_str(ftype.get()) > 0) {
    if (vlen == VariableStrings::kRefuse)
      return bad_input(what + ": variable-length strings are read only in a checked child process");
    Handle mtype(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mtype.get(), H5T_VARIABLE);
    H5Tset_cset(mtype.get(), H5Tget_cset(ftype.get()));  // libhdf5 converts no character set
    std::vector<char*> ptrs(n, nullptr);
    if (H5Aread(attr.get(), mtype.get(), ptrs.data()) < 0)
      return bad_input(what + " cannot be read (damaged file?)");
    std::size_t total = 0;
    for (char* p : ptrs) {
      const std::size_t len = p == nullptr ? 0 : strnlen(p, kMaxAttributeBytes + 1);
      total += len;
      if (total > kMaxAttributeBytes) break;
      out.emplace_back(p == nullptr ? "" : p, len);
    }
    H5Dvlen_reclaim(mtype.get(), space.get(), H5P_DEFAULT, ptrs.data());
    if (total > kMaxAttributeBytes)
      return bad_input(what + " is larger than " + std::to_string(kMaxAttributeBytes) + " bytes");
  } else {
    const std::size_t size = H5Tget_size(ftype.get());
    if (size == 0 || size > kMaxAttributeBytes || n * size > kMaxAttributeBytes) {
      return bad_input(what + " is larger than " + std::to_string(kMaxAttributeBytes) + " bytes");
    }
    Handle mtype(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mtype.get(), size);
    H5Tset_strpad(mtype.get(), H5T_STR_NULLPAD);
    H5Tset_cset(mtype.get(), H5Tget_cset(ftype.get()));
    std::vector<char> buf(n * size + 1, '\0');
    if (H5Aread(attr.get(), mtype.get(), buf.data()) < 0)
      return bad_input(what + " cannot be read (damaged file?)");
    for (std::size_t i = 0; i < n; ++i) {
      const char* s = buf.data() + i * size;
      out.emplace_back(s, strnlen(s, size));
    }
  }
  return Strings{std::move(out)};
}

// A scalar integer attribute of at most 64 bits: nullopt when absent or of another kind.
std::optional<long long> read_int_attribute(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return std::nullopt;
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  Handle ftype(H5Aget_type(attr.get()), H5Tclose);
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  if (!attr.valid() || !ftype.valid() || !space.valid() || H5Tget_class(ftype.get()) != H5T_INTEGER ||
      H5Tget_size(ftype.get()) > 8 || H5Sget_simple_extent_npoints(space.get()) != 1) {
    return std::nullopt;
  }
  long long v = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_LLONG, &v) < 0) return std::nullopt;
  return v;
}

}  // namespace tetra::h5io
