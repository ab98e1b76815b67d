// tetra — calibration, noise characterization, simulation, fault-tolerant fusion and DDS services
// for redundant gyro packages.

#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <string_view>

#include "cli_common.hpp"
#include "commands.hpp"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

constexpr Command kCommands[] = {
    {"calibrate", tetra::cli::cmd_calibrate, "estimate scale factors, biases and axes from turntable data"},
    {"allan", tetra::cli::cmd_allan, "Allan deviation and IEEE 952 noise terms of a gyro log"},
    {"sim", tetra::cli::cmd_sim, "simulate a unit: turntable, static, orbits, slews, faults"},
    {"replay", tetra::cli::cmd_replay, "run the fusion and fault-detection pipeline over a gyro log"},
    {"convert", tetra::cli::cmd_convert, "convert a gyro log between CSV and HDF5"},
    {"fusion", tetra::cli::cmd_fusion, "the fusion service on DDS"},
    {"monitor", tetra::cli::cmd_monitor, "ground monitoring of every unit on the DDS domain"},
    {"command", tetra::cli::cmd_command, "send an operator command (reset, exclude, reinstate) over DDS"},
    {"record", tetra::cli::cmd_record, "record the gyro streams seen on DDS as a replayable gyro log"},
    {"demo", tetra::cli::cmd_demo, "simulator + service + monitor on loopback with a fault mid-run"},
};

void print_usage(std::FILE* out) {
  std::fprintf(
      out, "usage: tetra COMMAND [OPTIONS]   (tetra COMMAND --help for a command's options)\n\ncommands:\n");
  for (const auto& c : kCommands) std::fprintf(out, "  %-10s %s\n", c.name, c.summary);
  std::fprintf(out, "  %-10s %s\n", "help", "this list");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(stderr);
    return tetra::cli::kExitBadInput;
  }
  const std::string_view name = argv[1];
  if (name == "help" || name == "--help" || name == "-h") {
    if (argc >= 3) {
      for (const auto& c : kCommands) {
        if (std::string_view(argv[2]) == c.name) {
          char help_flag[] = "--help";
          char* args[] = {argv[2], help_flag};
          return c.run(2, args);
        }
      }
    }
    print_usage(stdout);
    return tetra::cli::kExitOk;
  }
  for (const auto& c : kCommands) {
    if (name == c.name) {
      try {
        return c.run(argc - 1, argv + 1);
      } catch (const std::exception& e) {
        std::cerr << "tetra " << c.name << ": internal error: " << e.what() << '\n';
        return tetra::cli::kExitFailure;
      }
    }
  }
  std::cerr << "tetra: unknown command '" << name << "'\n";
  print_usage(stderr);
  return tetra::cli::kExitBadInput;
}
