#pragma once
// Reading input files within stated bounds (docs/formats.md, "Inputs"): regular files only (a FIFO
// is read too where nothing needs to seek it), with a clear error for a folder, a device such as
// /dev/zero, a socket, a missing or unreadable file, and a size limit per kind so that memory and
// time stay bounded for any input. Every error names the path.

#include <sys/types.h>

#include <cstddef>
#include <string>

#include "tetra/core/result.hpp"

namespace tetra {

//! [bytes] largest CSV table read (a 24 h, 100 Hz log of four gyros is about 0.6 GB).
inline constexpr std::size_t kMaxTableBytes = std::size_t{1} << 30;
//! [bytes] largest gyro log read block by block (GyroLogReader, CsvStreamReader): memory stays one
//! block whatever the length; a 24 h, 1 kHz log of four gyros is about 6 GB as CSV.
inline constexpr std::size_t kMaxStreamedLogBytes = std::size_t{1} << 40;
//! [bytes] longest line of a CSV read block by block (a row of kMaxColumns numbers is ~25 kB).
inline constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;
//! [bytes] largest YAML file read (calibrations, scenarios and configurations are a few kB).
inline constexpr std::size_t kMaxYamlBytes = std::size_t{1} << 20;

//! What a file of mode `mode` is, for messages: "a folder", "a FIFO", "a character device", ...
const char* file_kind(mode_t mode);

//! Checks that `path` can be read as an input: a regular file of at most `max_bytes` (or a FIFO when
//! `seekable` is false). Error (bad input) naming the path and what it is instead.
Status check_input(const std::string& path, std::size_t max_bytes, bool seekable);

//! Reads a whole input after check_input(path, max_bytes, false); a FIFO that delivers more than
//! `max_bytes` is an error, never an unbounded allocation.
Result<std::string> read_input(const std::string& path, std::size_t max_bytes);

}  // namespace tetra
