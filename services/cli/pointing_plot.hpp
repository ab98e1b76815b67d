#pragma once
// The closed-loop pointing plot (tetra/report/pointing_plot.hpp) under the names `tetra sim --closed-loop`
// uses. Its errors carry report::kPlotSubject (worded as --plot's by cli_common's report()).

#include "tetra/report/pointing_plot.hpp"

namespace tetra::cli {

using report::plot_pointing;
using report::PlottedRun;

}  // namespace tetra::cli
