// libFuzzer target: the HDF5 gyro log reader (core/src/gyro_log_h5.cpp, docs/formats.md) on arbitrary
// bytes taken as an in-memory HDF5 file image, read as the process that opens a file once the checking
// child process passed it: the header (gyro count and units from the last byte, which
// HDF5 ignores past the file's end: the corpus files are real HDF5 files with one byte appended) as the child
// would send it, then every dataset's shape, type, layout, filters and chunks checked and the rows read. The
// child's own work (the attributes: libhdf5 faults there are what it isolates) is not fuzzed in process;
// HostileH5.* and the regress_* inputs cover it.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_check.hpp"
#include "gyro_log_h5.hpp"

// libhdf5 (Debian's, not instrumented) sizes some allocations from the file before it checks them and
// handles a failed malloc as an error: the reader's checking child limits its address space so that
// such a malloc fails there (docs/formats.md); here a malloc of more than 1 GiB fails the same way
// (ASan returns null) instead of being reported as an out-of-memory. tetra's own allocations use new,
// which throws, so one of them over 1 GiB is still a crash. It also loses a few hundred bytes on some error
// paths of a damaged file: those leaks are not reported; every allocation of tetra's own code is still
// checked.
extern "C" const char* __asan_default_options() {  // NOLINT(readability-identifier-naming)
  return "allocator_may_return_null=1:max_allocation_size_mb=1024";
}
extern "C" const char* __lsan_default_suppressions() {  // NOLINT(readability-identifier-naming)
  return "leak:libhdf5\n";
}
// libhdf5 also reads out of bounds on some damaged metadata while it opens a dataset (a name in a layout
// message without its terminating NUL, copied by strdup): ASan sees that through its interceptors, the only
// part of an uninstrumented library it sees. The reader opens a file by name only after the checking child
// process opened every dataset the same way, so such a fault ends the child and the file is refused
// (HostileH5.*); here, in process, the interceptors called from libhdf5 are not reported. tetra's own code is
// instrumented and still checked everywhere.
extern "C" const char* __asan_default_suppressions() {  // NOLINT(readability-identifier-naming)
  return "interceptor_via_lib:libhdf5\n";
}

namespace {

// libhdf5 also faults outright on some damaged metadata while it opens a dataset (a division by zero in its
// chunk layout, a read far out of bounds): a file read by name meets that in the checking child, which dies
// by the signal, and the file is refused (HostileH5.FilesOnWhichLibhdf5FaultsAreRefusedByTheCheckingChild,
// tests/fuzz/libhdf5_faults/). Here the same opening runs first in a helper child of this process (forked
// once, fed each input through a pipe; the default action on those signals): an input that ends it so is
// one the reader never opens in process, and is not read here. The helper's verdict is only that: every
// input it survives is read below, instrumented.
class OpeningHelper {
 public:
  //! Whether opening `image` with `header` ends the helper by one of the faults the checking child meets (a
  //! fatal signal, or its alarm: a hang); it is started again next time.
  bool faults(std::span<const std::uint8_t> image, const tetra::GyroLogH5Header& header) {
    if (pid_ < 0 && !start()) return false;
    const std::uint64_t size = image.size();
    const auto info = static_cast<std::uint8_t>(header.gyro_count | (header.units_dps ? 0x80 : 0));
    char ack = 0;
    if (put(&size, sizeof size) && put(&info, 1) && put(image.data(), image.size()) && get(from_, &ack, 1))
      return false;
    int status = 0;
    ::close(to_);
    ::close(from_);
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    if (!WIFSIGNALED(status)) return false;
    const int sig = WTERMSIG(status);
    return std::find(kFaults.begin(), kFaults.end(), sig) != kFaults.end() || sig == SIGALRM;
  }

 private:
  bool start() {
    int in[2];
    int out[2];
    if (::pipe2(in, O_CLOEXEC) != 0) return false;
    if (::pipe2(out, O_CLOEXEC) != 0) {
      ::close(in[0]);
      ::close(in[1]);
      return false;
    }
    ::signal(SIGPIPE, SIG_IGN);  // a helper that died while fed: a failed write, not this process's end
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(in[1]);
      ::close(out[0]);
      serve(in[0], out[1]);
    }
    ::close(in[0]);
    ::close(out[1]);
    if (pid_ < 0) {
      ::close(in[1]);
      ::close(out[0]);
      return false;
    }
    to_ = in[1];
    from_ = out[0];
    return true;
  }
  [[noreturn]] static void serve(int from, int to) {
    for (const int sig : kFaults) ::signal(sig, SIG_DFL);
    ::signal(SIGALRM, SIG_DFL);  // not libFuzzer's timeout handler: a hang ends the helper
    std::vector<std::uint8_t> image;
    for (;;) {
      std::uint64_t size = 0;
      std::uint8_t info = 0;
      if (!get(from, &size, sizeof size) || !get(from, &info, 1)) ::_exit(0);
      image.resize(size);
      if (!get(from, image.data(), size)) ::_exit(0);
      tetra::GyroLogH5Header header;
      header.gyro_count = info & 0x7f;
      header.units_dps = (info & 0x80) != 0;
      ::alarm(
          kHelperSeconds);  // below libFuzzer's -timeout: a libhdf5 hang is the helper's, not the fuzzer's
      (void)tetra::open_gyro_log_h5_image(image, "fuzz.h5", header);
      ::alarm(0);
      const char ack = 1;
      if (::write(to, &ack, 1) != 1) ::_exit(0);
    }
  }
  //! `n` bytes through `io` (read or write, retried on EINTR): false at an end or an error.
  template <typename Io>
  static bool whole(Io io, std::size_t n) {
    std::size_t done = 0;
    while (done < n) {
      const ssize_t moved = io(done, n - done);
      if (moved < 0 && errno == EINTR) continue;
      if (moved <= 0) return false;
      done += static_cast<std::size_t>(moved);
    }
    return true;
  }
  static bool get(int fd, void* data, std::size_t n) {
    return whole(
        [&](std::size_t at, std::size_t left) { return ::read(fd, static_cast<char*>(data) + at, left); }, n);
  }
  bool put(const void* data, std::size_t n) const {
    return whole([&](std::size_t at,
                     std::size_t left) { return ::write(to_, static_cast<const char*>(data) + at, left); },
                 n);
  }

  //! The signals the checking child dies by when libhdf5 faults (gyro_log_h5_probe.cpp resets the same).
  static constexpr std::array<int, 5> kFaults = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
  static constexpr unsigned kHelperSeconds = 5;  //!< [s] longest one opening may take in the helper

  pid_t pid_ = -1;
  int to_ = -1;    //!< the helper's input
  int from_ = -1;  //!< its acknowledgements
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  tetra::GyroLogH5Header header;
  header.gyro_count = 1 + data[size - 1] % 4;
  header.units_dps = (data[size - 1] & 0x80) != 0;
  static OpeningHelper helper;
  if (helper.faults(std::span<const std::uint8_t>(data, size), header)) return 0;
  const auto log =
      tetra::read_gyro_log_h5_image(std::span<const std::uint8_t>(data, size), "fuzz.h5", header);
  if (!log) {
    tetra::fuzz::check_error_message(log.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(log->gyro_count >= 1);
  const auto n = static_cast<std::size_t>(log->gyro_count);
  const std::size_t epochs = log->epochs();
  TETRA_FUZZ_CHECK(log->values.size() == epochs * n);
  TETRA_FUZZ_CHECK(log->present.size() == epochs * n);
  for (const auto& c : log->comments) TETRA_FUZZ_CHECK(c.find('\n') == std::string::npos);
  for (std::size_t e = 0; e < epochs; ++e) {
    TETRA_FUZZ_CHECK(std::isfinite(log->time_s[e]));
    for (int g = 0; g < log->gyro_count; ++g) {
      if (!log->is_present(e, g)) TETRA_FUZZ_CHECK(std::isnan(log->value(e, g)));
    }
  }
  return 0;
}
