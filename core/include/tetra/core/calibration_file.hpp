#pragma once
// Calibration file (docs/interfaces.md §2.3), YAML. Unknown keys are an error; every error names the file,
// the line and the key. Units: scale factor [V/(deg/s)], bias [V], axis unit vector in B.
// Axes whose norm is within 1e-3 of one are accepted and normalized (tables are often printed to
// five decimals); others are rejected.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/csv.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/result.hpp"

namespace tetra {

struct GyroSigma {
  double scale_factor_V_per_dps = 0.0;             //!< [V/(deg/s)] 1σ
  double bias_V = 0.0;                             //!< [V] 1σ
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  //!< [-] 1σ per component
};

//! IEEE Std 952 noise terms of one gyro, in deg/s-based units (from `tetra allan`). All optional.
struct GyroNoise {
  std::optional<double> quantization_deg;              //!< Q [deg]
  std::optional<double> arw_dps_rtHz;                  //!< N [deg/s/√Hz] = [deg/√s]: σ_rate = N/√dt
  std::optional<double> bias_instability_dps;          //!< B [deg/s]
  std::optional<double> rate_random_walk_dps_per_rts;  //!< K [deg/s/√s]
  std::optional<double> rate_ramp_dps_per_s;           //!< R [deg/s²]
};

//! [V/(deg/s)] bounds of a scale factor's magnitude (a denormal or absurd value is refused on reading).
inline constexpr double kMinScaleFactor_V_per_dps = 1e-9;
inline constexpr double kMaxScaleFactor_V_per_dps = 1e9;

struct GyroCalibration {
  int id = 0;                                         //!< 1..N
  double scale_factor_V_per_dps = 0.0;                //!< s_i [V/(deg/s)]
  double bias_V = 0.0;                                //!< β_i [V]
  Eigen::Vector3d axis_B = Eigen::Vector3d::UnitX();  //!< h_i, unit vector in B
  std::optional<GyroSigma> sigma;                     //!< 1σ of the estimates
  std::optional<GyroNoise> noise;                     //!< measured noise
};

struct Calibration {
  std::string unit = "tetra-1";        //!< free text
  std::optional<double> latitude_deg;  //!< [deg] where it was calibrated (information)
  std::string method;                  //!< "sixteen-position", "batch", "factory", ...
  std::vector<GyroCalibration> gyros;  //!< ordered by id, ids 1..N

  int gyro_count() const { return static_cast<int>(gyros.size()); }
  //! N×3 axes (rows h_iᵀ).
  Eigen::MatrixX3d axes_B() const;
};

//! The seed's unit as built and calibrated: Table 4 scale factors and biases, Table 5 estimated axes
//! (normalized), and noise at the Table 6 level (N = 3e-5 deg/√s, B = 5e-6 deg/s).
Calibration seed_as_built_unit();

Result<Calibration> read_calibration(const std::string& path);
Result<Calibration> parse_calibration(const std::string& yaml_text, const std::string& source);
//! Validates: N ≥ 3, ids 1..N in order, finite values, scale factor ≠ 0, unit axes.
Status validate_calibration(const Calibration& cal, const std::string& source);

//! The calibration as YAML (yaml-cpp's emitter: any unit name round-trips); `comments` ("key=value",
//! e.g. provenance_metadata()) become comment lines at the top.
std::string format_calibration(const Calibration& cal, const Metadata& comments = {});
//! Writes one calibration file on its own (atomically; see RunFiles).
Status write_calibration(const std::string& path, const Calibration& cal);
//! Writes the calibration into an output of a run (committed with the run).
Status write_calibration(OutputFile& out, const Calibration& cal, const Metadata& comments);

}  // namespace tetra
