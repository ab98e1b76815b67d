#pragma once
// Gyro log (docs/interfaces.md §2.2): time_s,g1..gN[,ref_qw,ref_qx,ref_qy,ref_qz[,ref_stamp_s]].
// An empty gyro cell means "no sample this epoch" (present = 0); "nan" means an invalid sample
// (present = 1, value NaN). Values are volts unless the file says "# units=dps" (deg/s).
// Reference columns are all four or none; on a row they are all filled or all empty. The optional
// ref_stamp_s (CSV, with the reference columns) is the reference's own time where it was taken before its
// row's epoch (a late star tracker, as `tetra record` writes it); empty: taken at the row's time.
// The reader checks the format only: times that do not increase are left for the pipeline to
// reject and count.

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/output_files.hpp"
#include "tetra/core/result.hpp"

namespace tetra {

//! [s] the largest |time_s| a log may hold: time goes on as integer nanoseconds (int64, ±9.22e9 s).
inline constexpr double kMaxLogTime_s = 9.0e9;
//! Why `time_s` cannot be a log's time (not finite, or beyond ±kMaxLogTime_s), or nullopt.
std::optional<std::string> log_time_problem(double time_s);

struct GyroLog {
  std::string source;                                         //!< file name used in messages
  std::vector<std::pair<std::string, std::string>> metadata;  //!< "# key=value" comments, in order
  std::vector<std::string> comments;  //!< text after the '#' of each comment line, in order
  int gyro_count = 0;                 //!< N, columns g1..gN
  bool units_dps = false;             //!< values already rates [deg/s] ("# units=dps"), else [V]
  std::vector<double> time_s;         //!< [s] per epoch
  std::vector<double> values;         //!< [V or deg/s] epochs×N row-major; NaN where absent/invalid
  std::vector<std::uint8_t> present;  //!< epochs×N row-major; 0 where no sample was delivered
  bool has_reference = false;         //!< ref_* columns exist
  std::vector<std::array<double, 4>> reference_wxyz;  //!< body→reference quaternion per epoch
  std::vector<std::uint8_t> reference_present;        //!< 1 where the row carries a reference
  bool has_reference_stamp = false;                   //!< the ref_stamp_s column exists
  //! [s] per epoch, with has_reference_stamp: the reference's own time, NaN when it is the row's
  std::vector<double> reference_stamp_s;
  std::vector<std::size_t> lines;  //!< 1-based file line of each epoch

  std::size_t epochs() const { return time_s.size(); }
  double value(std::size_t epoch, int gyro_index0) const {
    return values[epoch * static_cast<std::size_t>(gyro_count) + static_cast<std::size_t>(gyro_index0)];
  }
  bool is_present(std::size_t epoch, int gyro_index0) const {
    return present[epoch * static_cast<std::size_t>(gyro_count) + static_cast<std::size_t>(gyro_index0)] != 0;
  }
  std::optional<std::string> meta(const std::string& key) const;
};

//! Reads a whole gyro log: CSV, HDF5 when the name ends in ".h5" or ".hdf5", TDMS when it ends in ".tdms"
//! (read as the table its channels make, tetra/core/tdms.hpp; docs/formats.md).
Result<GyroLog> read_gyro_log(const std::string& path);
Result<GyroLog> parse_gyro_log(std::string_view text, std::string source);

//! True when `path` names an HDF5 gyro log (".h5" or ".hdf5").
bool is_hdf5_path(const std::string& path);

//! Reads a gyro log block by block, memory bounded by one block whatever the log's length. Blocks are
//! GyroLog values holding a slice of the epochs (same metadata and columns; `lines` are file lines of
//! a CSV, 1-based rows of an HDF5 log). Errors are those of read_gyro_log.
class GyroLogReader {
 public:
  virtual ~GyroLogReader() = default;
  //! Opens a CSV, HDF5 or TDMS log (by the name's extension) and reads its header.
  static Result<std::unique_ptr<GyroLogReader>> open(const std::string& path);
  //! Source, metadata, gyro count, units and reference flag; no epochs.
  const GyroLog& header() const { return header_; }
  //! Replaces `block`'s epochs by the next ones (at least one). False at the end of the log.
  virtual Result<bool> next(GyroLog& block) = 0;
  //! Fraction of the log read so far, in [0, 1] (0 when unknown).
  virtual double fraction_read() const = 0;
  //! Epochs in the whole log when known before reading it (HDF5), else 0.
  virtual std::size_t epochs_hint() const { return 0; }

 protected:
  GyroLog header_;
};

class GyroLogH5Writer;

//! Streams a gyro log into an output of the output layer (OutputFile: written as it goes into its
//! temporary file): CSV, or HDF5 when the name ends in ".h5" or ".hdf5".
//! Numbers are written in shortest round-trip form: the same inputs give byte-identical files.
class GyroLogWriter {
 public:
  GyroLogWriter();
  GyroLogWriter(const GyroLogWriter&) = delete;
  GyroLogWriter& operator=(const GyroLogWriter&) = delete;
  ~GyroLogWriter();

  //! Opens `path` as a run of its own (RunFiles: atomic replace on close()); `comments` are written as
  //! "# key=value" lines before the header.
  Status open(const std::string& path, int gyro_count, bool with_reference, bool units_dps,
              const std::vector<std::pair<std::string, std::string>>& comments = {});
  //! Writes into an output of a larger run; close() flushes, the run's RunFiles::commit() commits.
  Status open(OutputFile& out, int gyro_count, bool with_reference, bool units_dps,
              const std::vector<std::pair<std::string, std::string>>& comments = {});
  //! Opens an output for a log shaped like `header` (gyro count, reference columns), with its comment
  //! lines as they are: a log read and written again is the same file when tetra wrote it.
  Status open_like(const std::string& path, const GyroLog& header);
  Status open_like(OutputFile& out, const GyroLog& header);
  //! One epoch. `present[i] == 0` writes an empty cell; NaN writes "nan".
  //! `reference_stamp_s`: the reference's own time when it was taken before `time_s` (written only with
  //! set_reference_stamps(true); nullopt: at `time_s`).
  Status write(double time_s, std::span<const double> values, std::span<const std::uint8_t> present,
               const std::optional<std::array<double, 4>>& reference_wxyz = std::nullopt,
               std::optional<double> reference_stamp_s = std::nullopt);
  //! Flushes and closes (and, when opened by path, commits: fsync and rename into place).
  Status close();
  //! HDF5 only, before open: shuffle + deflate every dataset (files 2-4x smaller, read about 5x slower).
  //! Default off: chunked, uncompressed datasets. CSV output ignores it.
  void set_hdf5_compression(bool compress) { compress_ = compress; }
  //! CSV only, before open: a ref_stamp_s column after the reference columns (open_like sets it from its
  //! header). An HDF5 output refuses it at open.
  void set_reference_stamps(bool with_stamps) { with_reference_stamp_ = with_stamps; }

 private:
  Result<OutputFile*> open_own(const std::string& path);
  Status open_output(OutputFile& out, int gyro_count, bool with_reference,
                     const std::vector<std::string>& comments);
  Status flush();
  std::unique_ptr<RunFiles> own_;  // a run of its own (the open() taking a path)
  OutputFile* out_ = nullptr;
  std::unique_ptr<GyroLogH5Writer> h5_;  // set while an HDF5 log is open
  std::string buffer_;
  int gyro_count_ = 0;
  bool with_reference_ = false;
  bool with_reference_stamp_ = false;
  bool compress_ = false;
};

}  // namespace tetra
