#pragma once
// Plumbing shared by the DDS subcommands: the --domain option, the local clock, the web folder's default,
// and the report library's formatting helpers (tetra/report/text.hpp).

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <dds/dds.h>
#include <CLI/CLI.hpp>

#include "tetra/dds/clock.hpp"
#include "tetra/report/text.hpp"

namespace tetra::cli {

//! Adds `--domain ID` (default: DDS_DOMAIN_DEFAULT, i.e. the Cyclone configuration's, normally 0) and
//! `--security PROFILE.yaml` (opt-in DDS Security for every participant of the process) and
//! `--data-representation xcdr1|xcdr2` (the encoding of the process's writers).
void add_domain_option(CLI::App& app, dds_domainid_t& domain);

using dds::monotonic_ns;
using dds::wall_ns;

//! Checks a unit name option (tetra/service/unit_name.hpp: 1 to 31 bytes of UTF-8, no control
//! characters); CLI11 names the option in the error.
CLI::Validator unit_name_check();

//! The ground station's web application: `../share/tetra/web` beside the program when it is installed
//! (cmake --install), else the source tree's `web/` the program was built from.
std::string default_web_dir();

using report::fixed;
using report::json_number;
using report::json_string;

}  // namespace tetra::cli
