#include "tetra/core/output_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace tetra {

namespace {

std::string errno_text() {
  return std::strerror(errno);
}

std::string dir_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string base_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::optional<std::string> real_path(const std::string& path) {
  char buf[PATH_MAX];
  if (::realpath(path.c_str(), buf) == nullptr) return std::nullopt;
  return std::string(buf);
}

// Follows a chain of symbolic links that ends at a name that does not exist yet (a dangling link
// is written through: the file it names is created). Returns the final path.
Result<std::string> follow_links(const std::string& path) {
  std::string current = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(current.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return current;
    char buf[PATH_MAX];
    const ssize_t n = ::readlink(current.c_str(), buf, sizeof buf - 1);
    if (n < 0) return bad_input(path + ": cannot read the symbolic link: " + errno_text());
    const std::string link(buf, static_cast<std::size_t>(n));
    current = link.front() == '/' ? link : dir_of(current) + "/" + link;
  }
  return bad_input(path + ": too many levels of symbolic links");
}

mode_t new_file_mode() {
  const mode_t mask = ::umask(0);
  ::umask(mask);
  return static_cast<mode_t>(0666 & ~mask);
}

Status write_all(int fd, std::string_view data, const std::string& path) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EPIPE) return failure(path + ": the reader closed the pipe (broken pipe)");
      return failure(path + ": write failed: " + errno_text());
    }
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  return ok_status();
}

}  // namespace

std::optional<FileId> file_id(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  return FileId{st.st_dev, st.st_ino};
}

OutputFile::~OutputFile() {
  discard();
}

Status OutputFile::write(std::string_view data) {
  if (fd_ < 0) return failure(path_ + ": output is closed");
  // Text printed through stdio or std::cout (synchronized with stdio) comes first on standard output.
  if (fd_ == STDOUT_FILENO) std::fflush(stdout);
  if (Status st = write_all(fd_, data, path_); !st) return st;
  written_bytes_ += static_cast<off_t>(data.size());
  return stream_ ? ok_status() : write_behind();
}

// A long output is sent to the disk as it grows: each full window is queued for writing, and the
// window before it, once on the disk, leaves the page cache. The cache then holds about two windows of
// the file whatever its length, and its pages are reused window after window instead of fresh memory
// being taken for every page of the file (on a virtual machine that returns free memory to its host,
// fresh pages cost several times the copy). Outputs shorter than a window are untouched. A write error
// that waiting for a window reports is returned here: the kernel reports it once, to this wait, and a
// later fsync would not see it again (the run then fails and the output is not committed).
Status OutputFile::write_behind() {
  constexpr off_t kWindowBytes = off_t{8} << 20;
  while (write_behind_ && written_bytes_ - queued_bytes_ >= kWindowBytes) {
    if (::sync_file_range(fd_, queued_bytes_, kWindowBytes, SYNC_FILE_RANGE_WRITE) != 0) {
      if (errno != EINVAL && errno != ESPIPE && errno != ENOSYS)
        return failure(path_ + ": cannot write: " + errno_text());
      write_behind_ = false;  // a file system without it: the file is written as any other
      break;
    }
    if (queued_bytes_ >= kWindowBytes) {
      const off_t previous = queued_bytes_ - kWindowBytes;
      if (::sync_file_range(
              fd_, previous, kWindowBytes,
              SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE | SYNC_FILE_RANGE_WAIT_AFTER) != 0)
        return failure(path_ + ": cannot write: " + errno_text());
      ::posix_fadvise(fd_, previous, kWindowBytes,
                      POSIX_FADV_DONTNEED);  // advice only: its result changes nothing
    }
    queued_bytes_ += kWindowBytes;
  }
  return ok_status();
}

Result<std::string> OutputFile::library_path() const {
  if (stream_) {
    return bad_input(label_ + " " + path_ + ": needs a regular file (it is written with seeks), not " +
                     (path_ == "-" ? "standard output" : "a device or FIFO"));
  }
  if (fd_ < 0) return failure(path_ + ": output is closed");
  return temp_;
}

Status OutputFile::sync() {
  if (stream_ || fd_ < 0) return ok_status();
  const bool synced = ::fsync(fd_) == 0;
  const std::string why = synced ? "" : errno_text();
  const bool closed = ::close(fd_) == 0;
  fd_ = -1;
  if (!synced || !closed) return failure(path_ + ": cannot write: " + (synced ? errno_text() : why));
  return ok_status();
}

Status OutputFile::rename_into_place() {
  if (stream_) return ok_status();
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    return failure(path_ + ": cannot replace: " + errno_text());
  }
  committed_ = true;
  // The rename itself reaches the disk with the folder.
  const int dir = ::open(dir_of(target_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  return ok_status();
}

void OutputFile::discard() {
  if (fd_ >= 0 && fd_ != STDOUT_FILENO) ::close(fd_);
  fd_ = -1;
  if (!stream_ && !committed_ && !temp_.empty()) ::unlink(temp_.c_str());
  temp_.clear();
}

Status BufferedOutput::flush() {
  if (Status st = out_.write(buffer_); !st) return st;
  buffer_.clear();
  return ok_status();
}

RunFiles::~RunFiles() = default;

void RunFiles::add_input(const std::string& path, const std::string& label) {
  input_paths_.push_back(path);
  if (const auto id = file_id(path)) inputs_.push_back({path, label, *id});
}

std::vector<std::string> RunFiles::input_paths() const {
  return input_paths_;
}

Status RunFiles::check_distinct(const OutputFile& out, const std::optional<FileId>& id,
                                const std::string& replaces_input) const {
  const std::string who = out.label_ + " " + out.path_;
  if (id) {
    for (const auto& in : inputs_) {
      if (in.id == *id && !(replaces_input == in.path && !replaces_input.empty())) {
        return bad_input(who + ": is the same file as the input " + in.label +
                         " (an output never replaces an input)");
      }
    }
  }
  for (const auto& other : outputs_) {
    const std::string them = other->label_ + " " + other->path_;
    if (out.path_ == "-" && other->path_ == "-")
      return bad_input(who + ": standard output is already the output of " + other->label_);
    if (out.path_ == "-" || other->path_ == "-") continue;
    const bool same_id = id && file_id(other->target_) == id;
    if (same_id && out.stream_) {
      struct stat st {};
      if (::stat(out.target_.c_str(), &st) == 0 && S_ISCHR(st.st_mode)) continue;  // /dev/null twice
    }
    if (same_id || out.target_ == other->target_)
      return bad_input(who + ": is the same file as the output " + them);
  }
  return ok_status();
}

Status RunFiles::add_outputs(std::initializer_list<OptionalOutput> outputs) {
  for (const OptionalOutput& o : outputs) {
    *o.slot = nullptr;
    if (o.path.empty()) continue;
    auto out = add(o.path, o.label);
    if (!out) return out.error();
    *o.slot = *out;
  }
  return ok_status();
}

Result<OutputFile*> RunFiles::add(const std::string& path, const std::string& label,
                                  const std::string& replaces_input) {
  auto out = std::unique_ptr<OutputFile>(new OutputFile());
  out->path_ = path;
  out->label_ = label;
  const std::string who = label + " " + path;
  if (path.empty()) return bad_input(label + ": empty file name");
  if (path == "-") {
    out->stream_ = true;
    out->target_ = "-";
    if (Status st = check_distinct(*out, std::nullopt, replaces_input); !st) return st.error();
    out->fd_ = STDOUT_FILENO;
    outputs_.push_back(std::move(out));
    return outputs_.back().get();
  }
  auto followed = follow_links(path);
  if (!followed) return bad_input(label + " " + followed.error().message);
  struct stat st {};
  const bool exists = ::stat(followed->c_str(), &st) == 0;
  std::optional<FileId> id;
  if (exists) {
    if (S_ISDIR(st.st_mode)) return bad_input(who + ": is a folder, not a file");
    if (!S_ISREG(st.st_mode) && !S_ISCHR(st.st_mode) && !S_ISFIFO(st.st_mode))
      return bad_input(who + ": is neither a regular file, a character device nor a FIFO");
    id = FileId{st.st_dev, st.st_ino};
    out->stream_ = !S_ISREG(st.st_mode);
  }
  const auto dir = real_path(dir_of(*followed));
  if (!dir) return bad_input(who + ": folder " + dir_of(*followed) + ": " + errno_text());
  out->target_ = (*dir == "/" ? "" : *dir) + "/" + base_of(*followed);
  if (Status s = check_distinct(*out, id, replaces_input); !s) return s.error();

  if (out->stream_) {
    out->fd_ = ::open(out->target_.c_str(), O_WRONLY | O_CLOEXEC);
    if (out->fd_ < 0) return bad_input(who + ": cannot open: " + errno_text());
  } else {
    std::string templ = *dir + "/." + base_of(*followed) + ".tetra-XXXXXX";
    out->fd_ = ::mkstemp(templ.data());
    if (out->fd_ < 0) return bad_input(who + ": cannot create a file in " + *dir + ": " + errno_text());
    out->temp_ = templ;
    const mode_t mode = exists ? static_cast<mode_t>(st.st_mode & 07777) : new_file_mode();
    ::fchmod(out->fd_, mode);
  }
  outputs_.push_back(std::move(out));
  return outputs_.back().get();
}

Status RunFiles::put(const std::string& path, const std::string& label, std::string_view content) {
  auto out = add(path, label);
  if (!out) return out.error();
  return (*out)->write(content);
}

Status RunFiles::commit() {
  for (auto& out : outputs_) {
    if (Status st = out->sync(); !st) return st;
  }
  for (auto& out : outputs_) {
    if (Status st = out->rename_into_place(); !st) return st;
  }
  return ok_status();
}

}  // namespace tetra
