#include "tetra/core/output_files.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "tetra/core/input_files.hpp"

namespace tetra {

namespace {

// --- temporary files removed on SIGINT, SIGTERM and SIGHUP --------------------------------------
// A fixed table the signal handler reads with lock-free atomics only: no allocation, no lock. A slot
// is claimed (1), filled, then published (2); the handler unlinks the published slots of its own
// process (a forked child inherits the table, never the files) and re-raises the signal with its
// default action, so the process still ends as the signal says.
struct TempSlot {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 live
  pid_t owner = 0;
  std::array<char, PATH_MAX> path{};
};
std::array<TempSlot, 64> g_temp_slots;

extern "C" void remove_temporaries_and_reraise(int sig) {
  const int saved_errno = errno;
  const pid_t self = ::getpid();
  for (TempSlot& slot : g_temp_slots) {
    if (slot.state.load() == 2 && slot.owner == self) ::unlink(slot.path.data());
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);  // delivered when the handler returns (the signal is blocked while it runs)
  errno = saved_errno;
}

// Installs the handler once, for each signal whose disposition is still the default: a command that
// handles or blocks a signal itself (the DDS services wait for them in a thread) keeps its own way.
void install_temp_removal() {
  static std::atomic<bool> installed{false};
  if (installed.exchange(true)) return;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) != 0 || (old.sa_flags & SA_SIGINFO) != 0 || old.sa_handler != SIG_DFL)
      continue;
    struct sigaction sa {};
    sa.sa_handler = remove_temporaries_and_reraise;
    sigemptyset(&sa.sa_mask);
    ::sigaction(sig, &sa, nullptr);
  }
}

// The slot now holding `path`, or -1 when the table is full or the path too long (the file is then
// only removed by a normal exit or failure, as before).
int register_temporary(const std::string& path) {
  install_temp_removal();
  if (path.size() >= PATH_MAX) return -1;
  for (std::size_t i = 0; i < g_temp_slots.size(); ++i) {
    TempSlot& slot = g_temp_slots[i];
    int expected = 0;
    if (!slot.state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slot.path.data(), path.c_str(), path.size() + 1);
    slot.owner = ::getpid();
    slot.state.store(2);
    return static_cast<int>(i);
  }
  return -1;
}

// mkstemp(templ) and its registration with the signals that remove temporaries blocked: a signal
// between the two (the file there, not yet in the table) would leave it behind. A pending signal is
// delivered once the slot is live. The descriptor, or -1 with errno set by mkstemp.
int create_registered_temporary(std::string& templ, int& slot) {
  install_temp_removal();
  sigset_t removal{};
  sigset_t previous{};
  sigemptyset(&removal);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&removal, sig);
  ::pthread_sigmask(SIG_BLOCK, &removal, &previous);
  const int fd = ::mkstemp(templ.data());
  const int saved_errno = errno;
  if (fd >= 0) slot = register_temporary(templ);
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  errno = saved_errno;
  return fd;
}

void unregister_temporary(int& slot) {
  if (slot >= 0) g_temp_slots[static_cast<std::size_t>(slot)].state.store(0);
  slot = -1;
}

// --- what may be an output ------------------------------------------------------------------------

// True for the null device (/dev/null, or another name of it).
bool is_null_device(const struct stat& st) {
  struct stat null_st {};
  return S_ISCHR(st.st_mode) && ::stat("/dev/null", &null_st) == 0 && S_ISCHR(null_st.st_mode) &&
         st.st_rdev == null_st.st_rdev;
}

// An existing regular file the caller may replace: one the kernel lets it write (access(2): mode
// bits, ACLs, a read-only file system) and, for root (whom the kernel lets write anything), one with
// at least one write bit: a write-protected file (chmod a-w) is never replaced, whoever runs.
bool may_replace(const std::string& path, const struct stat& st) {
  if (::geteuid() == 0)
    return (st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) != 0 && ::access(path.c_str(), W_OK) == 0;
  return ::access(path.c_str(), W_OK) == 0;
}

// Why an existing file cannot be an output (empty when it can): only regular files the caller may
// write and the null device are; a FIFO, a socket or another device is refused before anything is
// opened (opening a FIFO blocks until a reader comes).
std::string refusal(const std::string& path, const struct stat& st) {
  if (S_ISDIR(st.st_mode)) return "is a folder, not a file";
  if (S_ISREG(st.st_mode)) {
    return may_replace(path, st) ? "" : "is write-protected (no write permission): it is never replaced";
  }
  if (is_null_device(st)) return "";
  return std::string("is ") + file_kind(st.st_mode) +
         ": an output must be a regular file (`-` for standard output, /dev/null to discard)";
}

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
  constexpr off_t kWriteBehindBytes = off_t{8} << 20;
  while (write_behind_ && written_bytes_ - queued_bytes_ >= kWriteBehindBytes) {
    if (::sync_file_range(fd_, queued_bytes_, kWriteBehindBytes, SYNC_FILE_RANGE_WRITE) != 0) {
      if (errno != EINVAL && errno != ESPIPE && errno != ENOSYS)
        return failure(path_ + ": cannot write: " + errno_text());
      write_behind_ = false;  // a file system without it: the file is written as any other
      break;
    }
    if (queued_bytes_ >= kWriteBehindBytes) {
      const off_t previous = queued_bytes_ - kWriteBehindBytes;
      if (::sync_file_range(
              fd_, previous, kWriteBehindBytes,
              SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE | SYNC_FILE_RANGE_WAIT_AFTER) != 0)
        return failure(path_ + ": cannot write: " + errno_text());
      ::posix_fadvise(fd_, previous, kWriteBehindBytes,
                      POSIX_FADV_DONTNEED);  // advice only: its result changes nothing
    }
    queued_bytes_ += kWriteBehindBytes;
  }
  return ok_status();
}

Result<std::string> OutputFile::library_path() const {
  if (stream_) {
    return bad_input(label_ + " " + path_ + ": needs a regular file (it is written with seeks), not " +
                     (path_ == "-" ? "standard output" : "the null device"));
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
  unregister_temporary(temp_slot_);
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
  unregister_temporary(temp_slot_);
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
    if (const std::string why = refusal(*followed, st); !why.empty()) return bad_input(who + ": " + why);
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
    const int created = create_registered_temporary(templ, out->temp_slot_);
    out->fd_ = created;
    if (out->fd_ < 0) return bad_input(who + ": cannot create a file in " + *dir + ": " + errno_text());
    out->temp_ = templ;
    const mode_t mode = exists ? static_cast<mode_t>(st.st_mode & 07777) : new_file_mode();
    ::fchmod(out->fd_, mode);
  }
  outputs_.push_back(std::move(out));
  return outputs_.back().get();
}

Status check_output_path(const std::string& path, const std::string& label) {
  if (path.empty()) return bad_input(label + ": empty file name");
  if (path == "-") return ok_status();
  auto followed = follow_links(path);
  if (!followed) return bad_input(label + " " + followed.error().message);
  struct stat st {};
  if (::stat(followed->c_str(), &st) != 0) return ok_status();
  if (const std::string why = refusal(*followed, st); !why.empty())
    return bad_input(label + " " + path + ": " + why);
  return ok_status();
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
