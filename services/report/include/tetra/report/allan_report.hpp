#pragma once
// The Allan analysis of a gyro log as `tetra allan` reports it: the table (tetra/core/allan.hpp), the CSV,
// JSON, Kalibr imu.yaml and log-log plot, and the fitted noise terms written into a calibration file.

#include <ostream>
#include <string>
#include <vector>

#include "tetra/core/allan.hpp"
#include "tetra/core/result.hpp"
#include "tetra/report/argument_names.hpp"

namespace tetra::report {

struct AllanReportOptions {
  std::string log_path;             //!< gyro log (CSV or HDF5): volts, or deg/s with '# units=dps'
  std::string calibration_path;     //!< calibration YAML: volts become deg/s; empty: none
  bool update_calibration = false;  //!< write the fitted terms into calibration_path's noise: sections
  std::vector<int> gyros;           //!< gyros analysed (1..N); empty: all
  std::string taus = "default";     //!< averaging times (allan::parse_tau_spec)
  std::string csv_path;             //!< gyro,tau_s,adev,adev_lo,adev_hi,n; empty: none
  std::string json_path;            //!< the noise terms; empty: none
  std::string plot_path;            //!< log-log PNG (needs gnuplot); empty: none
  std::string kalibr_path;          //!< Kalibr's imu.yaml (needs calibration_path); empty: none
  double confidence = allan::kOneSigmaConfidence;  //!< two-sided confidence level of the intervals
  double dt_tolerance = 0.05;  //!< allowed deviation of a time step from a whole sampling interval
  bool progress = false;       //!< notes of progress on `err` (for a person watching)
  //! How messages name the arguments (log_path, update_calibration, ...) and the command ("command").
  ArgumentNames names;
};

struct AllanReport {
  allan::LogAllan analysis;
  bool calibration_updated = false;  //!< the noise terms were written into calibration_path
};

//! Error::subject of the report's errors about its arguments besides allan's own (kSubjectTaus, ...):
//! "update_calibration" and "kalibr_path" (need calibration_path), "dt_tolerance" and "confidence" (out
//! of range; the value as given), kPlotSubject (the plot).
//! Reads the log block by block (never whole), prints the table on `out` and notes on `err`, writes the
//! outputs asked for (all or none: through the output layer).
Result<AllanReport> write_allan_report(const AllanReportOptions& options, std::ostream& out,
                                       std::ostream& err);

}  // namespace tetra::report
