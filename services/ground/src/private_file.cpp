#include "tetra/ground/private_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace tetra::ground {

namespace {

//! The file a path names, through symbolic links (the path itself when it does not exist yet). A link to
//! nothing is bad input: replacing it would drop the link, following it would create a file elsewhere.
Result<std::string> target_of(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
  char resolved[PATH_MAX];
  if (::realpath(path.c_str(), resolved) == nullptr || ::stat(resolved, &st) != 0)
    return bad_input(path + ": a symbolic link to no file (" + std::strerror(errno) +
                     "): point it at the file, or remove it to start a new one");
  return std::string(resolved);
}

std::string mode_text(unsigned mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", mode & 07777U);
  return text;
}

}  // namespace

Status write_private(const std::string& path, const std::string& text) {
  const auto resolved = target_of(path);
  if (!resolved) return resolved.error();
  const std::string& target = *resolved;
  const std::string tmp = target + ".new" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return failure(path + ": cannot write (" + tmp + ")");
  const bool written =
      ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!written || ::rename(tmp.c_str(), target.c_str()) != 0) {
    ::unlink(tmp.c_str());
    return failure(path + ": cannot write");
  }
  return ok_status();
}

Status check_private(const std::string& path, const std::string& what, const std::string& risk) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return ok_status();
  if ((st.st_mode & 077U) != 0)
    return bad_input(path + ": " + what + " is readable or writable by group or others (mode " +
                     mode_text(st.st_mode) + "); " + risk + ": chmod 600 " + path);
  return ok_status();
}

FileStamp file_stamp(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {};
  return {static_cast<std::int64_t>(st.st_size),
          static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec};
}

}  // namespace tetra::ground
