#pragma once
// Shared plumbing of the `tetra` subcommands: argument parsing with CLI11 and the exit-status
// contract (0 success, 2 bad usage or bad input with one line on stderr, 1 any other failure).

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "tetra/core/result.hpp"

namespace tetra::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

//! Parses argv (argv[0] is the subcommand name). Returns an exit status when the command should
//! stop now (help printed → 0, bad usage → 2), or nullopt to go on.
std::optional<int> parse(CLI::App& app, int argc, char** argv);

//! Prints "tetra SUB: message" on stderr; returns 2 for bad input, 1 otherwise.
int report(const std::string& command, const Error& error);

}  // namespace tetra::cli
