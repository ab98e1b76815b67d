#pragma once
// The score's plot (`tetra score --plot`): the attitude error per body axis against its ±3σ envelope (the
// seed's Fig. 7, right side), one panel per axis.

#include <string>

#include "tetra/core/attitude_score.hpp"
#include "tetra/core/output_files.hpp"

namespace tetra::report {

//! Renders the plot with gnuplot and writes the PNG to `png` (through the output layer). `title` heads it.
//! Errors of the plot carry kPlotSubject.
Status write_score_plot(OutputFile& png, const AttitudeScore& score, const std::string& title);

}  // namespace tetra::report
