#pragma once
// `tetra sim SCENARIO.yaml --closed-loop`: its options (the run: tetra/report/closed_loop_files.hpp).

#include <CLI/CLI.hpp>

#include "tetra/report/closed_loop_files.hpp"

namespace tetra::cli {

struct ClosedLoopCliOptions : report::ClosedLoopOptions {
  bool enabled = false;  //!< --closed-loop
};

void add_closed_loop_options(CLI::App& app, ClosedLoopCliOptions& options);

}  // namespace tetra::cli
