// The input and output layers (docs/formats.md, "Inputs" and "Outputs"), strict numbers, metadata
// escapes, JSON UTF-8 and the flicker-rate EDF at m = 1.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/allan_stats.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/json.hpp"
#include "tetra/core/output_files.hpp"

namespace tetra {
namespace {

using test::read_file;
using test::TempDir;
using test::write_file;

bool has_temporary(const TempDir& dir) {
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    if (entry.path().filename().string().find(".tetra-") != std::string::npos) return true;
  }
  return false;
}

TEST(OutputFiles, OutputEqualToAnInputIsRefusedThroughLinks) {
  TempDir dir;
  write_file(dir.file("in.csv"), "data\n");
  std::filesystem::create_symlink(dir.file("in.csv"), dir.file("link.csv"));
  RunFiles files;
  files.add_input(dir.file("in.csv"), "LOG");
  const auto out = files.add(dir.file("link.csv"), "--attitude");
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.error().message.find("--attitude"), std::string::npos);
  EXPECT_NE(out.error().message.find("same file as the input LOG"), std::string::npos);
  EXPECT_EQ(read_file(dir.file("in.csv")), "data\n");
}

// A long output is sent to the disk and dropped from the page cache window by window as it is written
// (8 MB windows): the committed file is every byte written, in order, whatever the pieces' sizes.
TEST(OutputFiles, LongOutputWrittenBehindIsWhole) {
  TempDir dir;
  std::string expected;
  {
    RunFiles files;
    auto out = files.add(dir.file("long.csv"), "--attitude");
    ASSERT_TRUE(out.ok());
    for (int piece = 0; expected.size() < (std::size_t{26} << 20); ++piece) {
      // Pieces of 1 byte to ~1.3 MB, so window edges fall inside pieces.
      const std::string text(static_cast<std::size_t>(1 + (piece * 7919) % 1300000),
                             static_cast<char>('a' + piece % 26));
      expected += text;
      ASSERT_TRUE((*out)->write(text).ok());
    }
    ASSERT_TRUE(files.commit().ok());
  }
  EXPECT_TRUE(read_file(dir.file("long.csv")) == expected);
}

TEST(OutputFiles, TwoOutputsTheSameFileAreRefused) {
  TempDir dir;
  RunFiles files;
  ASSERT_TRUE(files.add(dir.file("a.csv"), "--csv").ok());
  const auto second = files.add(dir.path().string() + "/./a.csv", "--json");
  ASSERT_FALSE(second.ok());
  EXPECT_NE(second.error().message.find("same file as the output --csv"), std::string::npos);
}

TEST(OutputFiles, NothingChangesUntilCommitAndNoTemporaryIsLeft) {
  TempDir dir;
  write_file(dir.file("a.csv"), "old a\n");
  write_file(dir.file("b.csv"), "old b\n");
  {
    RunFiles files;
    ASSERT_TRUE(files.put(dir.file("a.csv"), "--a", "new a\n").ok());
    ASSERT_TRUE(files.put(dir.file("b.csv"), "--b", "new b\n").ok());
    EXPECT_EQ(read_file(dir.file("a.csv")), "old a\n");
    // The run fails here: no commit.
  }
  EXPECT_EQ(read_file(dir.file("a.csv")), "old a\n");
  EXPECT_EQ(read_file(dir.file("b.csv")), "old b\n");
  EXPECT_FALSE(has_temporary(dir));

  RunFiles files;
  ASSERT_TRUE(files.put(dir.file("a.csv"), "--a", "new a\n").ok());
  ASSERT_TRUE(files.commit().ok());
  EXPECT_EQ(read_file(dir.file("a.csv")), "new a\n");
  EXPECT_FALSE(has_temporary(dir));
}

TEST(OutputFiles, SymlinkIsWrittenThroughAndKeptAndModeKept) {
  TempDir dir;
  write_file(dir.file("real.yaml"), "old\n");
  ASSERT_EQ(::chmod(dir.file("real.yaml").c_str(), 0640), 0);
  std::filesystem::create_symlink("real.yaml", dir.file("link.yaml"));
  RunFiles files;
  ASSERT_TRUE(files.put(dir.file("link.yaml"), "-o", "new\n").ok());
  ASSERT_TRUE(files.commit().ok());
  EXPECT_TRUE(std::filesystem::is_symlink(dir.file("link.yaml")));
  EXPECT_EQ(read_file(dir.file("real.yaml")), "new\n");
  struct stat st {};
  ASSERT_EQ(::stat(dir.file("real.yaml").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640U);
}

TEST(OutputFiles, DevNullIsWrittenStraightNeverReplaced) {
  RunFiles files;
  auto out = files.add("/dev/null", "--attitude");
  ASSERT_TRUE(out.ok());
  EXPECT_TRUE((*out)->is_stream());
  ASSERT_TRUE(files.add("/dev/null", "--events").ok());  // a sink may take two outputs
  ASSERT_TRUE((*out)->write("x").ok());
  ASSERT_TRUE(files.commit().ok());
  struct stat st {};
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

// A FIFO would block the run until a reader comes (and an HDF5 library cannot seek it); a device other
// than /dev/null takes writes it does not keep. Both refused before anything is opened.
TEST(OutputFiles, FifosAndDevicesOtherThanDevNullAreRefused) {
  TempDir dir;
  ASSERT_EQ(::mkfifo(dir.file("fifo").c_str(), 0600), 0);
  std::filesystem::create_symlink(dir.file("fifo"), dir.file("to_fifo"));
  RunFiles files;
  for (const std::string& path : {dir.file("fifo"), dir.file("to_fifo")}) {
    const auto fifo = files.add(path, "--attitude");  // returns at once: nothing opens the FIFO
    ASSERT_FALSE(fifo.ok());
    EXPECT_EQ(fifo.error().message,
              "--attitude " + path +
                  ": is a FIFO: an output must be a regular file (`-` for standard output, "
                  "/dev/null to discard)");
  }
  const auto full = files.add("/dev/full", "-o");
  ASSERT_FALSE(full.ok());
  EXPECT_NE(full.error().message.find("-o /dev/full: is a character device"), std::string::npos);
  EXPECT_FALSE(check_output_path(dir.file("fifo"), "campaign output").ok());
  EXPECT_TRUE(check_output_path("/dev/null", "campaign output").ok());
  EXPECT_TRUE(check_output_path(dir.file("new.csv"), "campaign output").ok());
}

// The rename of a temporary file would go around a file's write protection: a file without write
// permission is refused instead, for root too (whom the kernel lets write anything) when no write bit
// is set at all. Its contents and mode stay.
TEST(OutputFiles, WriteProtectedFileIsNeverReplaced) {
  TempDir dir;
  write_file(dir.file("keep.csv"), "kept\n");
  ASSERT_EQ(::chmod(dir.file("keep.csv").c_str(), 0444), 0);
  RunFiles files;
  const auto out = files.add(dir.file("keep.csv"), "-o");
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.error().message, "-o " + dir.file("keep.csv") +
                                     ": is write-protected (no write permission): it is never replaced");
  EXPECT_FALSE(files.add(dir.file("keep.csv"), "--update", dir.file("keep.csv")).ok());
  EXPECT_FALSE(check_output_path(dir.file("keep.csv"), "campaign output").ok());
  EXPECT_EQ(read_file(dir.file("keep.csv")), "kept\n");
  EXPECT_FALSE(has_temporary(dir));
  ASSERT_EQ(::chmod(dir.file("keep.csv").c_str(), 0644), 0);
  EXPECT_TRUE(files.add(dir.file("keep.csv"), "-o").ok());
}

// SIGINT, SIGTERM or SIGHUP during a run: the temporary files go, the previous output stays, and the
// process still ends by the signal (a child process here, killing itself mid-write).
TEST(OutputFiles, SignalRemovesTemporaryFilesAndKeepsThePreviousOutput) {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    TempDir dir;
    write_file(dir.file("out.csv"), "previous\n");
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {  // the signals at their default action, as gtest leaves them
      RunFiles files;
      auto a = files.add(dir.file("out.csv"), "-o");
      auto b = files.add(dir.file("new.h5"), "--log");
      if (!a.ok() || !b.ok() || !(*a)->write("partial").ok() || !has_temporary(dir)) ::_exit(3);
      ::raise(sig);
      ::_exit(4);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status)) << "signal " << sig << ": status " << status;
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_FALSE(has_temporary(dir)) << "signal " << sig;
    EXPECT_EQ(read_file(dir.file("out.csv")), "previous\n");
    EXPECT_FALSE(std::filesystem::exists(dir.file("new.h5")));
  }
}

TEST(OutputFiles, FolderAndMissingFolderAreRefusedNamingTheOption) {
  TempDir dir;
  RunFiles files;
  const auto folder = files.add(dir.path().string(), "--csv");
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.error().message.find("--csv"), std::string::npos);
  const auto missing = files.add(dir.file("no/such.csv"), "--json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("--json"), std::string::npos);
}

TEST(InputFiles, FoldersDevicesAndSizeLimitsAreClearErrors) {
  TempDir dir;
  const auto folder = read_input(dir.path().string(), 100);
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.error().message.find("is a folder"), std::string::npos);
  const auto zero = read_input("/dev/zero", 100);
  ASSERT_FALSE(zero.ok());
  EXPECT_NE(zero.error().message.find("/dev/zero: is a character device"), std::string::npos);
  write_file(dir.file("big.yaml"), std::string(200, 'x'));
  const auto big = read_input(dir.file("big.yaml"), 100);
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.error().message.find("larger than the limit"), std::string::npos);
}

TEST(StrictNumbers, OnlyPlainDecimal) {
  EXPECT_TRUE(parse_decimal("-1.5e-3"));
  EXPECT_TRUE(parse_decimal("+2"));
  for (const char* bad : {"", "0x10", "0x1p3", "1,5", " 1", "1 ", "nan", "inf", "nan(1)", "1e999", "--1"}) {
    EXPECT_FALSE(parse_decimal(bad)) << bad;
  }
}

TEST(Metadata, AnyValueRoundTrips) {
  const std::string value = "a \"b\" \\ c,d%e\nf#g=h";
  std::string text;
  append_metadata(text, "unit", value);
  EXPECT_EQ(text.find('\n'), text.size() - 1);  // one line
  text += "time_s\n0\n";
  const auto table = parse_csv(text, "t.csv");
  ASSERT_TRUE(table.ok()) << table.error().message;
  EXPECT_EQ(table->meta("unit").value_or(""), value);
}

TEST(Json, InvalidUtf8BecomesReplacementCharacters) {
  std::string out;
  append_json_string(out, "ok \xC3\xA9 \xFF \xE2\x82 \xED\xA0\x80 \xF0\x9F\x98\x80");
  EXPECT_EQ(out, "\"ok \xC3\xA9 \\ufffd \\ufffd\\ufffd \\ufffd\\ufffd\\ufffd \xF0\x9F\x98\x80\"");
}

TEST(AllanEdf, FlickerRateAtMOneGrowsWithTheRecord) {
  // Howe, Allan & Barnes: 2(N-2)^2/(2.3N-4.9) at m = 1, about 0.87 N; near the m = 2 value
  // 5N^2/(8(N+6)) ≈ 0.62 N, never ~1 (tolerance 1e-9 relative: the formula evaluated directly).
  const double n = 10001.0;
  const double edf = allan::overlapping_avar_edf(allan::NoiseType::kFlickerRate, n, 1.0);
  EXPECT_NEAR(edf, 2.0 * (n - 2.0) * (n - 2.0) / (2.3 * n - 4.9), 1e-9 * edf);
  EXPECT_GT(edf, 0.8 * n);
  EXPECT_GT(edf, allan::overlapping_avar_edf(allan::NoiseType::kFlickerRate, n, 2.0));
}

}  // namespace
}  // namespace tetra
