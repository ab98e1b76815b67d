#pragma once
// Where an output file came from: tetra's version, the command line, the input files and the UTC
// time of the run. Written as "# key=value" metadata in every CSV, as comments in YAML and as a
// "provenance" object in JSON (docs/formats.md, "Provenance").

#include <string>
#include <utility>
#include <vector>

namespace tetra {

//! tetra's version (the project version of the build).
inline constexpr const char* kVersion = TETRA_VERSION;

struct Provenance {
  std::string version = kVersion;
  std::string command_line;         //!< the arguments joined by blanks, each quoted when needed
  std::vector<std::string> inputs;  //!< input file names, in the order given
  std::string created_utc;          //!< ISO 8601, e.g. 2026-01-31T12:00:00Z
};

//! The command line of this process, recorded once at start (by main()).
void record_command_line(int argc, char** argv);
//! A Provenance for this process with the given inputs and the current UTC time.
Provenance provenance(std::vector<std::string> inputs);
//! As "key=value" pairs: tetra_version, command, inputs (joined by ';'), created_utc.
std::vector<std::pair<std::string, std::string>> provenance_metadata(const Provenance& p);

}  // namespace tetra
