#include "tetra/core/text_writer.hpp"

#include <cerrno>
#include <cstring>

namespace tetra {

TextFileWriter::~TextFileWriter() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::remove((path_ + ".tmp").c_str());
  }
}

Status TextFileWriter::open(const std::string& path) {
  if (file_ != nullptr) return failure(path_ + ": writer already open");
  path_ = path;
  buffer_.clear();
  file_ = std::fopen((path + ".tmp").c_str(), "wb");
  if (file_ == nullptr) return failure(path + ": cannot write: " + std::strerror(errno));
  return ok_status();
}

Status TextFileWriter::flush() {
  if (file_ == nullptr) return failure("text writer is not open");
  if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    return failure(path_ + ": write failed");
  }
  buffer_.clear();
  return ok_status();
}

Status TextFileWriter::commit() {
  const Status flushed = flush();
  if (file_ == nullptr) return flushed;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  const std::string tmp = path_ + ".tmp";
  if (!flushed || !closed) {
    std::remove(tmp.c_str());
    return flushed ? failure(path_ + ": write failed") : flushed;
  }
  if (std::rename(tmp.c_str(), path_.c_str()) != 0) {
    std::remove(tmp.c_str());
    return failure(path_ + ": cannot rename temporary file: " + std::strerror(errno));
  }
  return ok_status();
}

}  // namespace tetra
