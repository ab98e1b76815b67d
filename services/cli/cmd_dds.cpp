// DDS commands — not yet part of this build.
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"

namespace tetra::cli {

namespace {
int unavailable(const char* name) {
  std::cerr << "tetra " << name << ": not available in this build\n";
  return kExitFailure;
}
}  // namespace

int cmd_fusion(int, char**) {
  return unavailable("fusion");
}
int cmd_monitor(int, char**) {
  return unavailable("monitor");
}
int cmd_command(int, char**) {
  return unavailable("command");
}
int cmd_record(int, char**) {
  return unavailable("record");
}
int cmd_play(int, char**) {
  return unavailable("play");
}
int cmd_ingest(int, char**) {
  return unavailable("ingest");
}
int cmd_demo(int, char**) {
  return unavailable("demo");
}
int cmd_ground(int, char**) {
  return unavailable("ground");
}

}  // namespace tetra::cli
