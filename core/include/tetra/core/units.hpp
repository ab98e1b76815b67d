#pragma once
// Physical constants and unit conversions. Inside the code everything is SI (rad, rad/s, s, V);
// files and the command line use degrees, deg/s, volts and seconds (docs/interfaces.md §1).

#include <cstdint>
#include <limits>
#include <numbers>

namespace tetra {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();  //!< "no value"
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;
inline constexpr double kArcsecToRad = kDegToRad / 3600.0;
inline constexpr double kEarthRate_rad_s = 7.2921159e-5;  //!< [rad/s] sidereal rotation rate of the Earth

inline constexpr std::int64_t kNanosPerSecond = 1'000'000'000;

//! [ns] seconds to integer nanoseconds, rounded to nearest.
inline std::int64_t seconds_to_ns(double t_s) {
  return static_cast<std::int64_t>(t_s * 1e9 + (t_s >= 0 ? 0.5 : -0.5));
}
//! [s] integer nanoseconds to seconds.
inline double ns_to_seconds(std::int64_t t_ns) {
  return static_cast<double>(t_ns) / 1e9;  // division: correctly rounded (39.98, not 39.980000000000004)
}

}  // namespace tetra
