#pragma once
// A text output written as it is produced: buffered appends to a temporary file, renamed into place by
// commit(). A writer destroyed before commit() removes the temporary file, so a failed run never
// leaves a truncated output behind. Memory is bounded by the buffer, whatever the output's length.

#include <cstdio>
#include <string>
#include <string_view>

#include "tetra/core/result.hpp"

namespace tetra {

class TextFileWriter {
 public:
  TextFileWriter() = default;
  TextFileWriter(const TextFileWriter&) = delete;
  TextFileWriter& operator=(const TextFileWriter&) = delete;
  ~TextFileWriter();

  //! Creates `path`.tmp.
  Status open(const std::string& path);
  //! The buffer to append to; call maybe_flush() after appending.
  std::string& buffer() { return buffer_; }
  //! Writes the buffer out once it holds more than about 1 MB.
  Status maybe_flush() { return buffer_.size() > kFlushBytes ? flush() : ok_status(); }
  //! Flushes, closes and renames into place.
  Status commit();

 private:
  static constexpr std::size_t kFlushBytes = std::size_t{1} << 20;
  Status flush();
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string buffer_;
};

}  // namespace tetra
