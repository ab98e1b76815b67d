#pragma once
// Turntable calibration as `tetra calibrate` reports it: the rotation plan, the scale factors, biases and
// axes with their 1σ (cf. seed Tables 3-5), optionally the per-sequence residuals beside another
// calibration's (seed Fig. 4), and the calibration file (docs/interfaces.md §2.3).

#include <optional>
#include <ostream>
#include <string>

#include "tetra/core/calibration.hpp"
#include "tetra/core/result.hpp"
#include "tetra/report/argument_names.hpp"

namespace tetra::report {

struct CalibrationReportOptions {
  std::string turntable_path;          //!< turntable log: sequence,time_s,inner_deg,outer_deg,g1..gN
  std::string output_path;             //!< calibration file to write ("-": standard output)
  std::optional<double> latitude_deg;  //!< [deg] geodetic latitude; default: the log's latitude_deg comment
  CalibrationMethod method = CalibrationMethod::kSixteen;
  BiasModel bias_model = BiasModel::kBody;  //!< kSixteen only
  std::string compare_path;  //!< another calibration, its residuals printed beside; empty: none
  std::string unit;          //!< unit name; default: the log's unit comment, else tetra-1
  std::string noise_path;    //!< calibration whose gyros carry noise: sections; empty: none
  double bias_instability_correlation_s = 100.0;  //!< [s] Gauss-Markov correlation time (with noise_path)
  //! How messages name the arguments (turntable_path, latitude_deg, ...) and the command ("command").
  ArgumentNames names;
};

//! Reads the log (pass by pass, never held), estimates the calibration, prints the tables on `out` and
//! notes on `err`, writes the calibration file. Bad input about "bias_model" (kBatch takes kBody only).
Result<CalibrationResult> write_calibration_report(const CalibrationReportOptions& options, std::ostream& out,
                                                   std::ostream& err);

}  // namespace tetra::report
