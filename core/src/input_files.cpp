#include "tetra/core/input_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace tetra {

namespace {

std::string size_text(std::size_t bytes) {
  if (bytes >= (std::size_t{1} << 30)) return std::to_string(bytes >> 30) + " GiB";
  if (bytes >= (std::size_t{1} << 20)) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

}  // namespace

const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISFIFO(mode)) return "a FIFO";
  return "not a regular file";
}

Status check_input(const std::string& path, std::size_t max_bytes, bool seekable) {
  if (path.empty()) return bad_input("empty input file name");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return bad_input(path + ": cannot open: " + std::strerror(errno));
  const bool fifo_ok = !seekable && S_ISFIFO(st.st_mode);
  if (!S_ISREG(st.st_mode) && !fifo_ok) {
    return bad_input(path + ": is " + file_kind(st.st_mode) + ", not a regular file" +
                     (S_ISFIFO(st.st_mode) ? " (this input is read more than once)" : ""));
  }
  if (S_ISREG(st.st_mode) && static_cast<std::size_t>(st.st_size) > max_bytes) {
    return bad_input(path + ": is larger than the limit of " + size_text(max_bytes) +
                     " for this kind of file");
  }
  if (::access(path.c_str(), R_OK) != 0) return bad_input(path + ": cannot open: " + std::strerror(errno));
  return ok_status();
}

Result<std::string> read_input(const std::string& path, std::size_t max_bytes) {
  if (Status st = check_input(path, max_bytes, false); !st) return st.error();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return bad_input(path + ": cannot open: " + std::strerror(errno));
  std::string data;
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && static_cast<std::size_t>(st.st_size) <= max_bytes)
    data.reserve(static_cast<std::size_t>(st.st_size));  // one allocation for a regular file
  char buf[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      return failure(path + ": read error: " + why);
    }
    if (n == 0) break;
    if (data.size() + static_cast<std::size_t>(n) > max_bytes) {
      ::close(fd);
      return bad_input(path + ": is larger than the limit of " + size_text(max_bytes) +
                       " for this kind of file");
    }
    data.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return data;
}

}  // namespace tetra
