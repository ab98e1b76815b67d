#pragma once
// Gyro log (docs/interfaces.md §2.2): time_s,g1..gN[,ref_qw,ref_qx,ref_qy,ref_qz].
// An empty gyro cell means "no sample this epoch" (present = 0); "nan" means an invalid sample
// (present = 1, value NaN). Values are volts unless the file says "# units=dps" (deg/s).
// Reference columns are all four or none; on a row they are all filled or all empty.
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

struct GyroLog {
  std::string source;                                         //!< file name used in messages
  std::vector<std::pair<std::string, std::string>> metadata;  //!< "# key=value" comments, in order
  int gyro_count = 0;                                         //!< N, columns g1..gN
  bool units_dps = false;             //!< values already rates [deg/s] ("# units=dps"), else [V]
  std::vector<double> time_s;         //!< [s] per epoch
  std::vector<double> values;         //!< [V or deg/s] epochs×N row-major; NaN where absent/invalid
  std::vector<std::uint8_t> present;  //!< epochs×N row-major; 0 where no sample was delivered
  bool has_reference = false;         //!< ref_* columns exist
  std::vector<std::array<double, 4>> reference_wxyz;  //!< body→reference quaternion per epoch
  std::vector<std::uint8_t> reference_present;        //!< 1 where the row carries a reference
  std::vector<std::size_t> lines;                     //!< 1-based file line of each epoch

  std::size_t epochs() const { return time_s.size(); }
  double value(std::size_t epoch, int gyro_index0) const {
    return values[epoch * static_cast<std::size_t>(gyro_count) + static_cast<std::size_t>(gyro_index0)];
  }
  bool is_present(std::size_t epoch, int gyro_index0) const {
    return present[epoch * static_cast<std::size_t>(gyro_count) + static_cast<std::size_t>(gyro_index0)] != 0;
  }
  std::optional<std::string> meta(const std::string& key) const;
};

Result<GyroLog> read_gyro_log(const std::string& path);
Result<GyroLog> parse_gyro_log(std::string_view text, std::string source);

//! Streams a gyro log to disk. Numbers are written in shortest round-trip form: the same inputs give
//! byte-identical files.
class GyroLogWriter {
 public:
  GyroLogWriter() = default;
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
  //! One epoch. `present[i] == 0` writes an empty cell; NaN writes "nan".
  Status write(double time_s, std::span<const double> values, std::span<const std::uint8_t> present,
               const std::optional<std::array<double, 4>>& reference_wxyz = std::nullopt);
  //! Flushes (and, when opened by path, renames into place).
  Status close();

 private:
  Status flush();
  std::unique_ptr<RunFiles> own_;
  OutputFile* out_ = nullptr;
  std::string buffer_;
  int gyro_count_ = 0;
  bool with_reference_ = false;
};

}  // namespace tetra
