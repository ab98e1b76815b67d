#pragma once
// The pieces of the HDF5 gyro log that its reader (gyro_log_h5.cpp), its checking child process
// (gyro_log_h5_probe.cpp) and its writer (gyro_log_h5_write.cpp) share: the layout's constants, the
// handle type, the library's start and the attributes. Private to tetra::core.

#include <hdf5.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "gyro_log_h5.hpp"
#include "tetra/core/result.hpp"
#include "tetra/core/units.hpp"

namespace tetra::h5io {

constexpr const char* kFormat = "tetra gyro log";
constexpr int kVersion = 1;
constexpr hsize_t kChunkRows = 65536;  // rows per chunk, and per block written
// Rows per block read: half a chunk (2.8 MB for 4 gyros and a reference); a chunk read raw serves two.
constexpr hsize_t kBlockRows = kChunkRows / 2;
constexpr unsigned kDeflateLevel = 1;  // with compression: the noise in gyro values barely compresses anyway
constexpr std::array<const char*, 4> kRefNames = {"ref_qw", "ref_qx", "ref_qy", "ref_qz"};
constexpr std::size_t kMaxAttributeBytes = std::size_t{16} << 20;  // [bytes] one string attribute read

using H5Header = GyroLogH5Header;

// Owns an HDF5 identifier.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*closer)(hid_t)) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      closer_ = o.closer_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  ~Handle() { reset(); }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  hid_t release() {
    const hid_t id = id_;
    id_ = H5I_INVALID_HID;
    return id;
  }
  void reset() {
    if (id_ >= 0 && closer_ != nullptr) closer_(id_);
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*closer_)(hid_t) = nullptr;
};

// Once, before any other HDF5 call: the library's error stack is never printed (tetra reports one
// line of its own, naming the file), and the library is not shut down at exit (after a failed write,
// e.g. a full disk, its shutdown would close the half-written file again and may crash; the process
// is ending and the temporary file is discarded anyway).
inline void init_hdf5() {
  static const bool done = [] {
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

inline std::string gyro_name(std::size_t index0) {
  return "g" + std::to_string(index0 + 1);
}

// Whether variable-length string attributes may be read. Their strings live in the file's global heap,
// whose damaged sizes libhdf5 follows without checking (a flipped size crashes it): they are read only
// in the child process that checks a file before it is opened (see probe_in_child).
enum class VariableStrings { kRead, kRefuse };

//! String attribute `name` of `obj` (fixed-length UTF-8, NUL-padded; `scalar`: one value, not a list).
bool write_string_attribute(hid_t obj, const char* name, const std::vector<std::string>& values, bool scalar);
bool write_int_attribute(hid_t obj, const char* name, int value);
//! Strings of a string attribute (scalar or 1-D; fixed or variable length): nullopt when absent, an
//! error when it is not strings or larger than kMaxAttributeBytes.
Result<std::optional<std::vector<std::string>>> read_string_attribute(hid_t obj, const char* name,
                                                                      const std::string& src,
                                                                      VariableStrings vlen);
//! A scalar integer attribute of at most 64 bits: nullopt when absent or of another kind.
std::optional<long long> read_int_attribute(hid_t obj, const char* name);

//! The whole check of a file by name in this process (what the child runs).
using Inspect = Result<H5Header> (*)(const std::string& path);
//! Runs `inspect(path)` in a child process and returns its header: a crash, a hang or an error there is
//! an error here naming the file (see gyro_log_h5_probe.cpp).
Result<H5Header> probe_in_child(const std::string& path, Inspect inspect);

}  // namespace tetra::h5io
