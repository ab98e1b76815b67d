// The values of a TDMS file (tdms_values.hpp): type sizes, raw values as doubles, timestamps as text.
#include "tdms_values.hpp"

#include <cstdio>
#include <ctime>

namespace tetra::tdms_detail {

namespace {

constexpr std::int64_t kSeconds1904To1970 = 2082844800;

template <class T>
void decode_as(const std::uint8_t* at, std::size_t n, std::size_t step, bool big, double* out,
               std::size_t out_step) {
  for (std::size_t i = 0; i < n; ++i)
    out[i * out_step] = static_cast<double>(Cursor::load<T>(at + i * step, big));
}

}  // namespace

std::string hex_type(std::uint32_t type) {
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%X", type);
  return hex;
}

// Size in bytes of one value of a fixed-size type, 0 for strings and unknown types.
std::size_t type_size(std::uint32_t type) {
  switch (type) {
    case 1:
    case 5:
    case kTdsBoolean:
      return 1;  // I8, U8, Boolean
    case 2:
    case 6:
      return 2;  // I16, U16
    case 3:
    case 7:
    case 9:
    case 0x19:
      return 4;  // I32, U32, SingleFloat (with unit)
    case 4:
    case 8:
    case 10:
    case 0x1A:
      return 8;  // I64, U64, DoubleFloat (with unit)
    case 0x08000C:
      return 8;  // ComplexSingleFloat
    case kTdsTimeStamp:
    case 0x10000D:
      return 16;  // TimeStamp, ComplexDoubleFloat
    default:
      return 0;
  }
}

bool is_numeric(std::uint32_t type) {
  return (type >= 1 && type <= 10) || type == 0x19 || type == 0x1A || type == kTdsBoolean;
}

// n values of a fixed-size numeric type, `step` bytes apart from `at`, as doubles `out_step` apart.
void decode(const std::uint8_t* at, std::size_t n, std::size_t step, std::uint32_t type, bool big,
            double* out, std::size_t out_step) {
  switch (type) {
    case 1:
      return decode_as<std::int8_t>(at, n, step, big, out, out_step);
    case 2:
      return decode_as<std::int16_t>(at, n, step, big, out, out_step);
    case 3:
      return decode_as<std::int32_t>(at, n, step, big, out, out_step);
    case 4:
      return decode_as<std::int64_t>(at, n, step, big, out, out_step);
    case 5:
    case kTdsBoolean:
      return decode_as<std::uint8_t>(at, n, step, big, out, out_step);
    case 6:
      return decode_as<std::uint16_t>(at, n, step, big, out, out_step);
    case 7:
      return decode_as<std::uint32_t>(at, n, step, big, out, out_step);
    case 8:
      return decode_as<std::uint64_t>(at, n, step, big, out, out_step);
    case 9:
    case 0x19:
      return decode_as<float>(at, n, step, big, out, out_step);
    default:
      return decode_as<double>(at, n, step, big, out, out_step);  // 10, 0x1A
  }
}

// A value of a fixed-size numeric type as a double.
double load_number(const std::uint8_t* at, std::uint32_t type, bool big) {
  double v = 0;
  decode(at, 1, 0, type, big, &v, 1);
  return v;
}

// A timestamp (seconds since 1904-01-01 UTC and 2^-64 fractions) as ISO 8601 UTC text.
std::string timestamp_text(std::int64_t seconds, std::uint64_t fractions) {
  const std::int64_t unix_s = seconds - kSeconds1904To1970;
  const auto t = static_cast<std::time_t>(unix_s);
  std::tm tm{};
  if (gmtime_r(&t, &tm) == nullptr) return std::to_string(seconds) + " s after 1904-01-01";
  char date[40];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%S", &tm);
  char micro[16];
  std::snprintf(micro, sizeof micro, ".%06llu",
                static_cast<unsigned long long>(static_cast<double>(fractions) * 0x1p-64 * 1e6) % 1000000ULL);
  return std::string(date) + micro + "Z";
}

}  // namespace tetra::tdms_detail
