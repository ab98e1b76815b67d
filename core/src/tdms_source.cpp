// Where a TDMS file's bytes come from (tdms_internal.hpp): a regular file read piece by piece with pread,
// or a FIFO read whole.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "tdms_internal.hpp"
#include "tetra/core/input_files.hpp"

namespace tetra::tdms_detail {

namespace {

class FileSource final : public Source {
 public:
  FileSource(std::string path, int fd, std::uint64_t size) : path_(std::move(path)), fd_(fd), size_(size) {}
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;
  ~FileSource() override { ::close(fd_); }
  std::uint64_t size() const override { return size_; }
  Result<const std::uint8_t*> read(std::uint64_t offset, std::size_t n) override {
    if (buffer_.size() < n) buffer_.resize(n);
    std::size_t got = 0;
    while (got < n) {
      const ssize_t r = ::pread(fd_, buffer_.data() + got, n - got, static_cast<off_t>(offset + got));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) return failure(path_ + ": read error: " + std::strerror(errno));
      if (r == 0) {
        return bad_input(path_ + ": the file ends at byte " + std::to_string(offset + got) + ", not " +
                         std::to_string(size_) + ": it changed while it was read");
      }
      got += static_cast<std::size_t>(r);
    }
    return buffer_.data();
  }

 private:
  std::string path_;
  int fd_;
  std::uint64_t size_;
  std::vector<std::uint8_t> buffer_;
};

// A FIFO's bytes, held whole.
class HeldSource final : public Source {
 public:
  explicit HeldSource(std::string bytes) : bytes_(std::move(bytes)) {}
  std::uint64_t size() const override { return bytes_.size(); }
  Result<const std::uint8_t*> read(std::uint64_t offset, std::size_t /*n*/) override {
    return reinterpret_cast<const std::uint8_t*>(bytes_.data()) + offset;
  }

 private:
  std::string bytes_;
};

}  // namespace

Result<std::unique_ptr<Source>> open_source(const std::string& path) {
  if (Status s = check_input(path, kMaxStreamedLogBytes, false); !s) return s.error();
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISFIFO(st.st_mode)) {  // it cannot be read twice
    auto bytes = read_input(path, kMaxTdmsBytes);
    if (!bytes) return bytes.error();
    return std::unique_ptr<Source>(std::make_unique<HeldSource>(std::move(*bytes)));
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return bad_input(path + ": cannot open: " + std::strerror(errno));
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return bad_input(path + ": is not a regular file");
  }
  return std::unique_ptr<Source>(
      std::make_unique<FileSource>(path, fd, static_cast<std::uint64_t>(st.st_size)));
}

}  // namespace tetra::tdms_detail
