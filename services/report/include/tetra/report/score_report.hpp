#pragma once
// The score of an attitude estimate against the simulator's truth as `tetra score` reports it: the
// figures (tetra/core/attitude_score.hpp) printed as a table, written as JSON and plotted against ±3σ.

#include <ostream>
#include <string>

#include "tetra/core/attitude_score.hpp"
#include "tetra/core/result.hpp"
#include "tetra/report/argument_names.hpp"

namespace tetra::report {

struct ScoreReportOptions {
  std::string attitude_path;       //!< attitude rows (docs/interfaces.md §2.4), e.g. tetra replay's
  std::string truth_path;          //!< truth rows time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps
  std::string plot_path;           //!< PNG: the error per axis against ±3σ (needs gnuplot); empty: none
  std::string json_path;           //!< the figures as JSON; empty: none
  std::string axis = "y";          //!< axis of the integrated angle: x, y, z or a body vector "a,b,c"
  double time_tolerance_s = 1e-6;  //!< [s] an attitude row and a truth row this close are the same epoch
  ArgumentNames names;             //!< how messages name the paths (attitude_path, truth_path, ...)
};

//! Error::subject of the report's errors about its arguments: "axis" (with the text as its value),
//! "time_tolerance_s", "axis_B" (score_attitude's), kPlotSubject (the plot).
inline constexpr const char* kSubjectAxis = "axis";

//! Reads both files, scores the attitude, prints the table on `out`, writes the JSON and the plot asked
//! for (all or none: through the output layer). Returns the score.
Result<AttitudeScore> write_score_report(const ScoreReportOptions& options, std::ostream& out);

}  // namespace tetra::report
