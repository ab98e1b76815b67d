#pragma once
// PNG plot of closed-loop runs (gnuplot): pointing error (truth and estimated) against the bound,
// with the fault onsets; wheel speeds and wheel torques of the first run.

#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/sim/closed_loop_run.hpp"

namespace tetra::report {

struct PlottedRun {
  std::string label;                    //!< legend, e.g. "with exclusion"
  const sim::ClosedLoopRecord* record;  //!< the run
};

Status plot_pointing(const std::string& png_path, const std::vector<PlottedRun>& runs, double bound_deg,
                     const std::vector<double>& onsets_s, const std::string& title);

}  // namespace tetra::report
