#pragma once
// Shared plumbing of the `tetra` subcommands: argument parsing with CLI11 and the exit-status
// contract (0 success, 2 bad usage or bad input with one line on stderr, 1 any other failure).

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "tetra/core/result.hpp"

namespace tetra::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

//! Parses argv (argv[0] is the subcommand name). Returns an exit status when the command should
//! stop now (help printed → 0, bad usage → 2), or nullopt to go on.
std::optional<int> parse(CLI::App& app, int argc, char** argv);

//! A numeric option's range check, worded briefly: "'1e300' must be from 0 to 45" ("above MIN and at
//! most MAX" with `above_min`); NaN and infinities fail (CLI11's Range and PositiveNumber let NaN through
//! and print a 300-digit bound for an infinite one).
CLI::Validator number_in(double min, double max, bool above_min = false);

//! How a command words an Error about an argument of a library call (Error::subject): `format`
//! names the command's option and may use {value} (the subject's value) and {message}, e.g.
//! {"taus", "--taus: {message}"}, {"gyros", "--gyro {value}: {message}"}.
struct SubjectOption {
  std::string_view subject;
  std::string_view format;
};

//! The error's one line for the user: worded by the entry for its subject, else (a plot's error,
//! report::kPlotSubject) as --plot's, else in the library's words (describe()).
std::string user_message(const Error& error, std::initializer_list<SubjectOption> options);

//! Prints "tetra SUB: message" on stderr (user_message); returns 2 for bad input, 1 otherwise.
int report(const std::string& command, const Error& error, std::initializer_list<SubjectOption> options = {});

}  // namespace tetra::cli
