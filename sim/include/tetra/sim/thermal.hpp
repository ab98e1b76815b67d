#pragma once
// A warm-up: the unit's temperature follows a first-order transient from `start_C` to `end_C`,
//
//   T(t) = T_end + (T_start − T_end) · exp(−t/τ)                                   [°C]
//
// and each gyro's bias moves with it by its own coefficient, b_i(t) = c_i · (T(t) − T_cal) [deg/s], T_cal the
// temperature its calibration was made at (the settled temperature unless stated). The term enters the gyro's
// chain with the true rate, before noise, quantization and saturation (gyro_model.hpp), so the unit's own
// output carries it as a real warming unit's would. Common-mode (all c_i alike) and differential parts
// alike: the parity sees only the differential one.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace tetra::sim {

struct ThermalOptions {
  double start_C = 20.0;           //!< [°C] the unit's temperature at t = 0
  double end_C = 20.0;             //!< [°C] the temperature it settles at
  double time_constant_s = 300.0;  //!< [s] τ of the transient
  double calibrated_at_C = std::numeric_limits<double>::quiet_NaN();  //!< [°C] T_cal; NaN: end_C
  std::vector<double> bias_dps_per_K;  //!< [deg/s/K] c_i per gyro; empty: no thermal term

  bool active() const { return !bias_dps_per_K.empty(); }
  //! [°C] T(t).
  double temperature_C(double t_s) const {
    return end_C + (start_C - end_C) * std::exp(-std::max(t_s, 0.0) / time_constant_s);
  }
  //! [deg/s] gyro `gyro0`'s (0-based) thermal bias at `t_s`; 0 without the term.
  double bias_dps(std::size_t gyro0, double t_s) const {
    if (gyro0 >= bias_dps_per_K.size()) return 0.0;
    const double cal_C = std::isnan(calibrated_at_C) ? end_C : calibrated_at_C;
    return bias_dps_per_K[gyro0] * (temperature_C(t_s) - cal_C);
  }
};

//! [deg/s] the largest thermal bias a scenario may give a gyro (|c_i|·|T − T_cal| over the run).
inline constexpr double kMaxThermalBias_dps = 1.0;
//! [°C] the temperatures' range.
inline constexpr double kMinTemperature_C = -100.0;
inline constexpr double kMaxTemperature_C = 150.0;

}  // namespace tetra::sim
