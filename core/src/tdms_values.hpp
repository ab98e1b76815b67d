#pragma once
// The values of a TDMS file (tdms.cpp, tdms_values.cpp): data type codes and sizes, bounded reading of a
// region in a segment's byte order, raw values decoded as doubles, property values as text.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace tetra::tdms_detail {

// tdsDataType codes
constexpr std::uint32_t kTdsString = 0x20;
constexpr std::uint32_t kTdsBoolean = 0x21;
constexpr std::uint32_t kTdsTimeStamp = 0x44;

// Bounded reading of one region of the image in the segment's byte order.
class Cursor {
 public:
  Cursor(const std::uint8_t* bytes, std::size_t n, bool big_endian)
      : bytes_(bytes), end_(n), big_(big_endian) {}
  std::size_t left() const { return end_ - pos_; }
  bool take(std::size_t n, const std::uint8_t*& at) {
    if (n > left()) return false;
    at = bytes_ + pos_;
    pos_ += n;
    return true;
  }
  template <class T>
  bool get(T& out) {
    const std::uint8_t* at = nullptr;
    if (!take(sizeof(T), at)) return false;
    out = load<T>(at, big_);
    return true;
  }
  bool text(std::string& out) {
    std::uint32_t n = 0;
    const std::uint8_t* at = nullptr;
    if (!get(n) || !take(n, at)) return false;
    out.assign(reinterpret_cast<const char*>(at), n);
    return true;
  }
  template <class T>
  static T load(const std::uint8_t* at, bool big_endian) {
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, at, sizeof(T));
    if (big_endian) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

 private:
  const std::uint8_t* bytes_;
  std::size_t pos_ = 0;
  std::size_t end_;
  bool big_;
};

//! "0x…" of a data type code, for messages.
std::string hex_type(std::uint32_t type);
//! Size in bytes of one value of a fixed-size type, 0 for strings and unknown types.
std::size_t type_size(std::uint32_t type);
//! Integer, floating-point or boolean (kept as doubles).
bool is_numeric(std::uint32_t type);
//! n values of a fixed-size numeric type, `step` bytes apart from `at`, as doubles `out_step` apart.
void decode(const std::uint8_t* at, std::size_t n, std::size_t step, std::uint32_t type, bool big,
            double* out, std::size_t out_step);
//! A value of a fixed-size numeric type as a double.
double load_number(const std::uint8_t* at, std::uint32_t type, bool big);
//! A timestamp (seconds since 1904-01-01 UTC and 2^-64 fractions) as ISO 8601 UTC text.
std::string timestamp_text(std::int64_t seconds, std::uint64_t fractions);

}  // namespace tetra::tdms_detail
