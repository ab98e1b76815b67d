#pragma once
// A turntable log visited in passes (the input of the calibration estimators): every pass visits the
// rows in file order. Two sources: a TurntableLog in memory, and a file whose rows are never all in
// memory (TurntableFileRows), so `tetra calibrate` needs the same memory for a log of any length.

#include <cstddef>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "tetra/core/csv.hpp"
#include "tetra/core/result.hpp"
#include "tetra/core/turntable_log.hpp"

namespace tetra {

//! One row of a turntable log as a pass visits it.
struct TurntableRow {
  std::size_t index = 0;        //!< 0-based row of the log
  std::size_t line = 0;         //!< 1-based file line (index + 1 for a log built in memory)
  int sequence = 0;             //!< plan index (1-based)
  double time_s = 0.0;          //!< [s]
  double inner_deg = 0.0;       //!< [deg] inner gimbal encoder
  double outer_deg = 0.0;       //!< [deg] outer gimbal encoder
  const double* g_V = nullptr;  //!< [V] the N gyro outputs
};

using TurntableRowVisitor = std::function<void(const TurntableRow&)>;

class TurntableRows {
 public:
  virtual ~TurntableRows() = default;
  virtual const std::string& source() const = 0;  //!< file name used in messages
  virtual int gyro_count() const = 0;             //!< N
  virtual std::size_t rows() const = 0;
  virtual const Metadata& metadata() const = 0;  //!< "# key=value" comments, whole file, in order
  std::optional<std::string> meta(const std::string& key) const { return last_meta(metadata(), key); }
  //! Visits every row in file order. An error only when the source cannot be read again.
  virtual Status for_each(const TurntableRowVisitor& visit) const = 0;
};

//! The rows of a log in memory (which must outlive this view).
class TurntableLogRows final : public TurntableRows {
 public:
  explicit TurntableLogRows(const TurntableLog& log) : log_(log) {}
  const std::string& source() const override { return log_.source; }
  int gyro_count() const override { return log_.gyro_count; }
  std::size_t rows() const override { return log_.rows(); }
  const Metadata& metadata() const override { return log_.metadata; }
  Status for_each(const TurntableRowVisitor& visit) const override;

 private:
  const TurntableLog& log_;
};

//! A turntable log file read once by open() with every check of read_turntable_log (the same messages
//! and lines), its rows kept in an unnamed temporary binary file (8·(5 + N) bytes a row, on disk, never
//! in memory) that each pass reads a block at a time. Memory: a block of text on open, 64 kB per pass.
class TurntableFileRows final : public TurntableRows {
 public:
  TurntableFileRows() = default;
  TurntableFileRows(const TurntableFileRows&) = delete;
  TurntableFileRows& operator=(const TurntableFileRows&) = delete;
  ~TurntableFileRows() override;

  Status open(const std::string& path);
  const std::string& source() const override { return source_; }
  int gyro_count() const override { return gyro_count_; }
  std::size_t rows() const override { return rows_; }
  const Metadata& metadata() const override { return metadata_; }
  Status for_each(const TurntableRowVisitor& visit) const override;

 private:
  Status spill_rows(CsvStreamReader& reader, std::size_t header_entries);
  std::string source_;
  Metadata metadata_;
  int gyro_count_ = 0;
  std::size_t rows_ = 0;
  std::FILE* spill_ = nullptr;
};

}  // namespace tetra
