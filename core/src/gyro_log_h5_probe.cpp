// The checking child process of the HDF5 gyro log reader (gyro_log_h5_internal.hpp, probe_in_child).
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "gyro_log_h5_internal.hpp"

namespace tetra::h5io {

namespace {

constexpr unsigned kProbeSeconds = 30;  // [s] longest the child may take to check a file

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TETRA_H5_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define TETRA_H5_ASAN 1
#endif

// libhdf5 sizes some buffers from the file before checking them (an object header claiming 5 GB): in
// the child, such a malloc fails (an error, the file refused) instead of reserving gigabytes. The limit
// is the child's address space at the fork plus kProbeExtraBytes. Not under AddressSanitizer, whose
// shadow memory is terabytes of address space (there, its own allocation limit applies).
void limit_child_memory() {
#ifndef TETRA_H5_ASAN
  constexpr rlim_t kProbeExtraBytes = rlim_t{2} << 30;  // [bytes] address space the child may add
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  unsigned long pages = 0;
  const bool got = statm != nullptr && std::fscanf(statm, "%lu", &pages) == 1;
  if (statm != nullptr) std::fclose(statm);
  if (!got) return;
  const auto now = static_cast<rlim_t>(pages) * static_cast<rlim_t>(::sysconf(_SC_PAGESIZE));
  const struct rlimit limit { now + kProbeExtraBytes, now + kProbeExtraBytes };
  ::setrlimit(RLIMIT_AS, &limit);
#endif
}

std::string encode_header(const H5Header& h) {
  std::string out = "H" + std::to_string(h.gyro_count) + "\n" + (h.units_dps ? "dps" : "V") + "\n" +
                    std::to_string(h.comments.size()) + "\n";
  for (const std::string& c : h.comments) out += std::to_string(c.size()) + "\n" + c;
  return out;
}

// The child's answer: a header, or an error ("E", then 'b' bad input or 'f' failure, then the message).
Result<H5Header> decode_answer(const std::string& text, const std::string& path) {
  const Error garbled = failure(path + ": the process checking the file gave no answer");
  if (text.size() >= 2 && text[0] == 'E') {
    return Error{text.substr(2), text[1] == 'b' ? ErrorKind::kBadInput : ErrorKind::kFailure};
  }
  if (text.empty() || text[0] != 'H') return garbled;
  std::size_t pos = 1;
  auto number = [&](unsigned long long& v) {
    const std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) return false;
    try {
      v = std::stoull(text.substr(pos, end - pos));
    } catch (...) {
      return false;
    }
    pos = end + 1;
    return true;
  };
  H5Header h;
  unsigned long long count = 0;
  unsigned long long n = 0;
  if (!number(count)) return garbled;
  h.gyro_count = static_cast<int>(count);
  const std::size_t end = text.find('\n', pos);
  if (end == std::string::npos) return garbled;
  h.units_dps = text.compare(pos, end - pos, "dps") == 0;
  pos = end + 1;
  if (!number(n)) return garbled;
  for (unsigned long long i = 0; i < n; ++i) {
    unsigned long long len = 0;
    if (!number(len) || len > text.size() - pos) return garbled;
    h.comments.push_back(text.substr(pos, len));
    pos += len;
  }
  return h;
}

}  // namespace

// libhdf5 trusts the sizes it reads from a file's metadata: some damage (a flipped size in the global
// heap, where variable-length strings live) makes it read out of bounds and crash, and no check from
// outside the library can see it first. So a file is first opened and checked whole (its metadata,
// not its rows) in a child process, which sends the header back; a crash, a hang (kProbeSeconds) or
// an error there is an error value here naming the file, and this process then opens only a file that
// passed, reading no variable-length string itself.
Result<H5Header> probe_in_child(const std::string& path, Inspect inspect) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return failure(path + ": cannot create a pipe: " + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return failure(path + ": cannot start the process that checks it: " + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    // A fault of libhdf5 ends the child by its signal, whatever handler the host process installed (a
    // crash reporter, an interpreter's): the parent names the signal.
    for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::signal(sig, SIG_DFL);
    ::alarm(kProbeSeconds);
    limit_child_memory();
    const auto header = inspect(path);
    const std::string answer = header ? encode_header(*header)
                                      : std::string("E") +
                                            (header.error().kind == ErrorKind::kBadInput ? "b" : "f") +
                                            header.error().message;
    std::size_t done = 0;
    while (done < answer.size()) {
      const ssize_t n = ::write(fds[1], answer.data() + done, answer.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    ::_exit(0);  // no exit handlers: the parent's files and libraries are left as they are
  }
  ::close(fds[1]);
  std::string answer;
  std::array<char, 65536> buf{};
  while (answer.size() <= kMaxAttributeBytes * 2) {
    const ssize_t n = ::read(fds[0], buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    answer.append(buf.data(), static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status)) {
    if (WTERMSIG(status) == SIGALRM) {
      return bad_input(path + ": checking this HDF5 file took longer than " + std::to_string(kProbeSeconds) +
                       " s (damaged file?); nothing was read from it");
    }
    return bad_input(path + ": damaged HDF5 file: the HDF5 library failed on it (" +
                     strsignal(WTERMSIG(status)) +
                     ") in the process that checks files first; nothing was read from it");
  }
  return decode_answer(answer, path);
}

}  // namespace tetra::h5io
