// tetra — calibration, noise characterization, simulation, fault-tolerant fusion and DDS services
// for redundant gyro packages.

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <string_view>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/core/provenance.hpp"

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
    {"score", tetra::cli::cmd_score, "attitude error, NEES and sigma bounds of an estimate against truth"},
    {"convert", tetra::cli::cmd_convert, "convert a gyro log (CSV, HDF5, TDMS) to CSV or HDF5"},
    {"fusion", tetra::cli::cmd_fusion, "the fusion service on DDS"},
    {"monitor", tetra::cli::cmd_monitor, "ground monitoring of every unit on the DDS domain"},
    {"command", tetra::cli::cmd_command, "send an operator command (reset, exclude, reinstate) over DDS"},
    {"record", tetra::cli::cmd_record, "record the gyro streams seen on DDS as a replayable gyro log"},
    {"ingest", tetra::cli::cmd_ingest,
     "publish live gyro samples on DDS from a line protocol (stdin, UDP, serial)"},
    {"play", tetra::cli::cmd_play,
     "play a gyro log (CSV, HDF5, TDMS) on DDS at its pace, faster or in lockstep"},
    {"ground", tetra::cli::cmd_ground, "the ground station in the browser: DDS to HTTP bridge, Open MCT"},
    {"demo", tetra::cli::cmd_demo, "simulator + service + monitor on loopback with a fault mid-run"},
    {"campaign", tetra::cli::cmd_campaign,
     "fault-injection campaign, closed or open loop, in process or over DDS, with a report"},
};

void print_usage(std::FILE* out) {
  std::fprintf(
      out, "usage: tetra COMMAND [OPTIONS]   (tetra COMMAND --help for a command's options)\n\ncommands:\n");
  for (const auto& c : kCommands) std::fprintf(out, "  %-10s %s\n", c.name, c.summary);
  std::fprintf(out, "  %-10s %s\n", "help", "this list (help COMMAND: that command's options)");
  std::fprintf(out, "  %-10s %s\n", "--version", "tetra's version");
}

int help(int argc, char** argv) {
  if (argc < 3) {
    print_usage(stdout);
    return tetra::cli::kExitOk;
  }
  if (argc > 3) {
    std::cerr << "tetra help: give one command name (tetra help COMMAND)\n";
    return tetra::cli::kExitBadInput;
  }
  for (const auto& c : kCommands) {
    if (std::string_view(argv[2]) == c.name) {
      char help_flag[] = "--help";
      char* args[] = {argv[2], help_flag};
      return c.run(2, args);
    }
  }
  std::cerr << "tetra help: unknown command '" << tetra::one_line(argv[2]) << "' (tetra help lists them)\n";
  return tetra::cli::kExitBadInput;
}

}  // namespace

namespace {

//! Standard input, output and error closed by the caller (`<&-`): /dev/null in their place, so the first
//! file or socket the run opens never becomes "standard input" (ingest would read a DDS socket and never
//! end) or "standard output" (a `-o -` would go into it).
void reserve_standard_descriptors() {
  for (int fd = 0; fd <= 2; ++fd) {
    if (::fcntl(fd, F_GETFD) >= 0 || errno != EBADF) continue;
    const int null_fd = ::open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);
    if (null_fd >= 0 && null_fd != fd) {
      (void)::dup2(null_fd, fd);
      ::close(null_fd);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  reserve_standard_descriptors();
  // A closed pipe on standard output is a write error (EPIPE) that each writer reports, never a
  // signal that kills the run before its files are written.
  std::signal(SIGPIPE, SIG_IGN);
  tetra::record_command_line(argc, argv);
  if (argc < 2) {
    print_usage(stderr);
    return tetra::cli::kExitBadInput;
  }
  const std::string_view name = argv[1];
  if (name == "--version") {
    std::cout << "tetra " << tetra::kVersion << "\n";
    return tetra::cli::kExitOk;
  }
  if (name == "help" || name == "--help" || name == "-h") return help(argc, argv);
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
  std::cerr << "tetra: unknown command '" << tetra::one_line(std::string(name))
            << "' (tetra help lists them)\n";
  return tetra::cli::kExitBadInput;
}
