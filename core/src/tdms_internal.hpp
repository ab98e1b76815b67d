#pragma once
// Shared by the TDMS reader's files (tdms.cpp, tdms_source.cpp, tdms_table.cpp): where a file's bytes
// come from and where its values go, so that a log is read without holding the file or a second copy of
// its values (docs/formats.md, "TDMS", Memory).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/core/tdms.hpp"

namespace tetra::tdms_detail {

//! The bytes of a TDMS file: an image in memory, or a file read where the parser needs it.
class Source {
 public:
  virtual ~Source() = default;
  virtual std::uint64_t size() const = 0;
  //! Bytes [offset, offset + n) (within size()); valid until the next call.
  virtual Result<const std::uint8_t*> read(std::uint64_t offset, std::size_t n) = 0;
};

class MemorySource final : public Source {
 public:
  explicit MemorySource(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::uint64_t size() const override { return bytes_.size(); }
  Result<const std::uint8_t*> read(std::uint64_t offset, std::size_t /*n*/) override {
    return bytes_.data() + offset;
  }

 private:
  std::span<const std::uint8_t> bytes_;
};

//! A regular file, read piece by piece (memory: the largest piece asked for); a FIFO, which cannot be
//! read twice, read whole into memory (at most kMaxTdmsBytes). Errors name the path.
Result<std::unique_ptr<Source>> open_source(const std::string& path);

//! What one pass over the file does with the numeric channels' values.
enum class Pass {
  keep,   //!< into each TdmsChannel::values
  count,  //!< counted (TdmsChannel::value_count) and never read
  fill,   //!< written where a Fill says; channels it does not name are skipped unread
};

//! The cells a fill pass writes: value k of channel c goes to column[c][k * stride].
struct Fill {
  std::vector<double*> column;  //!< per channel (file order): its first cell, or nullptr
  std::size_t stride = 1;       //!< cells from one row to the next
  std::size_t rows = 0;         //!< values each named channel has (the count pass's figure)
};

//! Parses the file from `src` (`name` in messages). `fill` is used (and required) with Pass::fill.
Result<TdmsFile> parse(Source& src, const std::string& name, Pass pass, const Fill* fill = nullptr);

}  // namespace tetra::tdms_detail
