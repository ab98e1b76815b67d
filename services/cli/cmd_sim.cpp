// tetra sim — not yet part of this build.
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"

namespace tetra::cli {

int cmd_sim(int /*argc*/, char** /*argv*/) {
  std::cerr << "tetra sim: not available in this build\n";
  return kExitFailure;
}

}  // namespace tetra::cli
