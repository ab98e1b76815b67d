#pragma once
// HDF5 gyro logs (docs/formats.md): the CSV's columns as chunked (optionally compressed) datasets and its
// metadata as attributes. Private to tetra::core; reached through read_gyro_log, GyroLogReader and
// GyroLogWriter.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/gyro_log.hpp"
#include "tetra/core/result.hpp"

namespace tetra {

//! The whole log, as read_gyro_log.
Result<GyroLog> read_gyro_log_h5(const std::string& path);
//! A log's header as its root attributes give it (the checking child process sends it to the process
//! that then opens the file).
struct GyroLogH5Header {
  int gyro_count = 0;
  bool units_dps = false;
  std::vector<std::string> comments;
};
//! The whole log from an in-memory image of an HDF5 file (`name` names it in messages), read as the
//! process that opens a file after the child checked it: with `header` as the child sent it, reading no
//! attribute; every dataset's shape, type and storage checked, then the rows. For fuzzing that path.
Result<GyroLog> read_gyro_log_h5_image(std::span<const std::uint8_t> bytes, const std::string& name,
                                       const GyroLogH5Header& header);
//! The first step of read_gyro_log_h5_image alone: the image opened and every dataset's shape, type and
//! storage checked, no row read. libhdf5 faults on some damaged metadata right there (the checking child
//! meets that in a file read by name); the fuzzer runs this step in a child of its own first.
Status open_gyro_log_h5_image(std::span<const std::uint8_t> bytes, const std::string& name,
                              const GyroLogH5Header& header);
//! A block reader, as GyroLogReader::open. The file is first checked in a child process
//! (docs/formats.md, "HDF5 gyro log").
Result<std::unique_ptr<GyroLogReader>> open_gyro_log_h5_reader(const std::string& path);

//! Writes an HDF5 log into `file_path`: the temporary file of an OutputFile (OutputFile::library_path),
//! committed with the run's other outputs (RunFiles::commit).
class GyroLogH5Writer {
 public:
  GyroLogH5Writer();
  GyroLogH5Writer(const GyroLogH5Writer&) = delete;
  GyroLogH5Writer& operator=(const GyroLogH5Writer&) = delete;
  ~GyroLogH5Writer();

  //! `path` names the output in messages. `comments` are the CSV's comment lines (text after '#'), kept
  //! verbatim; units are "dps" when their last "units" entry says so. `compress`: shuffle + deflate
  //! (level 1) on every dataset; else the datasets are chunked only (read about 5x faster, 3-4x larger).
  Status open(const std::string& file_path, const std::string& path, int gyro_count, bool with_reference,
              const std::vector<std::string>& comments, bool compress);
  Status write(double time_s, std::span<const double> values, std::span<const std::uint8_t> present,
               const std::optional<std::array<double, 4>>& reference_wxyz);
  //! Flushes and closes the file (the run commits it).
  Status close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tetra
