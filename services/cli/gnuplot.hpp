#pragma once
// The report library's gnuplot plumbing (tetra/report/gnuplot.hpp) under the names the campaign report
// uses.

#include "tetra/report/gnuplot.hpp"

namespace tetra::cli {

using report::gp_quote;
using report::run_gnuplot;
using report::TempDir;

}  // namespace tetra::cli
