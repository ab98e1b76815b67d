// tetra calibrate — not yet part of this build.
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"

namespace tetra::cli {

int cmd_calibrate(int /*argc*/, char** /*argv*/) {
  std::cerr << "tetra calibrate: not available in this build\n";
  return kExitFailure;
}

}  // namespace tetra::cli
