// Hostile HDF5 gyro logs (docs/formats.md, "HDF5 gyro log"; docs/reliability.md): files made here with
// libhdf5 as a careless or hostile writer would make them, read through tetra's reader and command line.
// Every case ends in an error value naming the file (exit 2), never a crash, a hang or garbage read.
#include <hdf5.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/gyro_log.hpp"

namespace tetra {
namespace {

using test::TempDir;

// How the file deviates from what tetra writes.
struct Hostile {
  bool variable_strings = true;  // string attributes as variable-length strings (tetra before fixed ones)
  hsize_t declared_rows = 10;    // rows the datasets declare
  hsize_t written_rows = 10;     // rows actually written (the first ones)
  std::string external_g1;       // g1 stored in this external file instead of the HDF5 file
  bool fletcher32_g1 = false;    // g1 with a checksum filter tetra does not write
  std::vector<std::string> comments = {" units=V", " note=plain"};
  std::string units = "V";
};

void string_attribute(hid_t obj, const char* name, const std::vector<std::string>& values, bool scalar,
                      bool variable) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  std::size_t size = 1;
  for (const auto& v : values) size = std::max(size, v.size() + 1);
  H5Tset_size(type, variable ? H5T_VARIABLE : size);
  const hsize_t n = values.size();
  const hid_t space = scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr);
  const hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  if (variable) {
    std::vector<const char*> ptrs;
    for (const auto& v : values) ptrs.push_back(v.c_str());
    H5Awrite(attr, type, ptrs.data());
  } else {
    std::vector<char> buf(n * size, '\0');
    for (std::size_t i = 0; i < values.size(); ++i)
      std::memcpy(&buf[i * size], values[i].data(), values[i].size());
    H5Awrite(attr, type, buf.data());
  }
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
}

void int_attribute(hid_t obj, const char* name, int value) {
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(obj, name, H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, H5T_NATIVE_INT, &value);
  H5Aclose(attr);
  H5Sclose(space);
}

void dataset(hid_t file, const char* name, hid_t type, hid_t mem_type, hsize_t cols, const Hostile& h,
             const void* rows) {
  const int rank = cols > 1 ? 2 : 1;
  const std::array<hsize_t, 2> dims{h.declared_rows, cols};
  const std::array<hsize_t, 2> max{H5S_UNLIMITED, cols};
  const std::array<hsize_t, 2> chunk{64, cols};
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  const bool external = !h.external_g1.empty() && std::string(name) == "g1";
  if (external) {
    H5Pset_external(dcpl, h.external_g1.c_str(), 0, h.declared_rows * cols * H5Tget_size(type));
  } else {
    H5Pset_chunk(dcpl, rank, chunk.data());
    if (h.fletcher32_g1 && std::string(name) == "g1") H5Pset_fletcher32(dcpl);
  }
  const hid_t space = H5Screate_simple(rank, dims.data(), external ? nullptr : max.data());
  const hid_t d = H5Dcreate2(file, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  if (!external && h.written_rows > 0) {
    const std::array<hsize_t, 2> start{0, 0};
    const std::array<hsize_t, 2> count{h.written_rows, cols};
    H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
    const hid_t mspace = H5Screate_simple(rank, count.data(), nullptr);
    H5Dwrite(d, mem_type, mspace, space, H5P_DEFAULT, rows);
    H5Sclose(mspace);
  }
  H5Dclose(d);
  H5Sclose(space);
  H5Pclose(dcpl);
}

// A one-gyro log of `h.written_rows` rows (time 0.01 s apart, g1 = 0.5 V) made as `h` says.
void write_log(const std::string& path, const Hostile& h) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  string_attribute(file, "format", {"tetra gyro log"}, true, h.variable_strings);
  int_attribute(file, "version", 1);
  int_attribute(file, "gyro_count", 1);
  string_attribute(file, "units", {h.units}, true, h.variable_strings);
  string_attribute(file, "comments", h.comments, false, h.variable_strings);
  std::vector<double> time(h.written_rows);
  std::vector<double> g1(h.written_rows, 0.5);
  std::vector<std::uint8_t> present(h.written_rows, 1);
  for (std::size_t i = 0; i < time.size(); ++i) time[i] = 0.01 * static_cast<double>(i);
  dataset(file, "time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, h, time.data());
  dataset(file, "g1", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, h, g1.data());
  dataset(file, "present", H5T_STD_U8LE, H5T_NATIVE_UINT8, 1, h, present.data());
  H5Fclose(file);
}

// Runs `tetra ARGS` and checks it ended by itself (no signal) with `status`, naming `path` on stderr.
void expect_cli_refuses(const std::string& args, const std::string& path, int status = 2) {
  const auto r = test::run_tetra(args);
  EXPECT_EQ(r.exit_status, status) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
}

TEST(HostileH5, OldVariableLengthStringsStillRead) {
  TempDir dir;
  write_log(dir.file("old.h5"), Hostile{});
  const auto log = read_gyro_log(dir.file("old.h5"));
  ASSERT_TRUE(log.ok()) << log.error().message;
  EXPECT_EQ(log->epochs(), 10U);
  EXPECT_EQ(log->comments.size(), 2U);
  Hostile fixed;
  fixed.variable_strings = false;
  write_log(dir.file("fixed.h5"), fixed);
  EXPECT_TRUE(read_gyro_log(dir.file("fixed.h5")).ok());
}

// The global heap holds variable-length strings; a flipped object size there made libhdf5 read far out
// of bounds (a segfault in H5HG_read from the attribute read). The file is checked in a child process
// first: the crash stays there and is an error value here.
TEST(HostileH5, FlippedGlobalHeapSizeIsAnErrorNotACrash) {
  TempDir dir;
  write_log(dir.file("old.h5"), Hostile{});
  std::string bytes = test::read_file(dir.file("old.h5"));
  const auto gcol = bytes.find("GCOL");
  ASSERT_NE(gcol, std::string::npos);
  // Collection header: signature 4, version 1, reserved 3, size 8; then the first object: index 2,
  // reference count 2, reserved 4, size 8 (its size at +24).
  const std::uint64_t huge = 0x7fffffffffff0000ULL;
  std::memcpy(&bytes[gcol + 24], &huge, 8);
  test::write_file(dir.file("heap.h5"), bytes);
  const auto log = read_gyro_log(dir.file("heap.h5"));
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.error().message.rfind(dir.file("heap.h5"), 0), 0U) << log.error().message;
  for (const std::string& cmd :
       {"convert " + dir.file("heap.h5") + " " + dir.file("out.csv"), "allan " + dir.file("heap.h5")}) {
    expect_cli_refuses(cmd, "heap.h5");
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.csv")));
}

// Eight random bytes flipped in the first 6 KB of 30 logs (a fixed seed): each read ends in a log or an
// error value, and the command line ends by itself with 0 or 2 leaving no temporary file.
TEST(HostileH5, ThirtyLogsWithEightFlippedBytes) {
  TempDir dir;
  write_log(dir.file("old.h5"), Hostile{});
  const std::string clean = test::read_file(dir.file("old.h5"));
  const std::size_t span = std::min<std::size_t>(clean.size(), 6144);
  std::mt19937 rng(26);
  int refused = 0;
  for (int k = 0; k < 30; ++k) {
    std::string bytes = clean;
    const std::size_t at = rng() % (span - 8);
    for (std::size_t i = 0; i < 8; ++i)
      bytes[at + i] = static_cast<char>(bytes[at + i] ^ static_cast<char>(1 + rng() % 255));
    const std::string path = dir.file("flip" + std::to_string(k) + ".h5");
    test::write_file(path, bytes);
    const auto log = read_gyro_log(path);
    if (!log.ok()) {
      ++refused;
      EXPECT_EQ(log.error().message.rfind(path, 0), 0U) << log.error().message;
    }
    const auto r = test::run_tetra("convert " + path + " " + dir.file("out.csv"));
    EXPECT_TRUE(r.exit_status == 0 || r.exit_status == 2)
        << path << ": status " << r.exit_status << " " << r.err;
  }
  EXPECT_GT(refused, 0);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".tetra-"), std::string::npos) << entry.path();
  }
}

// 2^40 rows declared, 10 written: the unwritten chunks would read as fill values forever.
TEST(HostileH5, RowsDeclaredButNotWrittenAreRefused) {
  TempDir dir;
  Hostile h;
  h.variable_strings = false;
  h.declared_rows = hsize_t{1} << 40;
  write_log(dir.file("huge.h5"), h);
  EXPECT_LT(std::filesystem::file_size(dir.file("huge.h5")), 64U * 1024);
  const auto log = read_gyro_log(dir.file("huge.h5"));
  ASSERT_FALSE(log.ok());
  EXPECT_NE(log.error().message.find("huge.h5: dataset 'time_s': declares 1099511627776 rows"),
            std::string::npos)
      << log.error().message;
  h.declared_rows = 100000;  // fewer than a 7 KB file could hold raw, still not written
  write_log(dir.file("unwritten.h5"), h);
  const auto partial = read_gyro_log(dir.file("unwritten.h5"));
  ASSERT_FALSE(partial.ok());
  EXPECT_NE(partial.error().message.find("written"), std::string::npos) << partial.error().message;
  expect_cli_refuses("convert " + dir.file("huge.h5") + " " + dir.file("out.csv"), "huge.h5");
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.csv")));
}

// External storage: read as gyro data from another local file, or blocking on a FIFO. Both refused
// before anything is read.
TEST(HostileH5, ExternalStorageIsRefused) {
  TempDir dir;
  test::write_file(dir.file("other.bin"), std::string(80, '\x3f'));
  ASSERT_EQ(::mkfifo(dir.file("fifo.bin").c_str(), 0600), 0);
  for (const char* target : {"other.bin", "fifo.bin"}) {
    Hostile h;
    h.variable_strings = false;
    h.external_g1 = dir.file(target);
    write_log(dir.file("ext.h5"), h);
    const auto log = read_gyro_log(dir.file("ext.h5"));
    ASSERT_FALSE(log.ok()) << target;
    EXPECT_EQ(log.error().message, dir.file("ext.h5") +
                                       ": dataset 'g1': stored in external files, which tetra does not read "
                                       "(docs/formats.md)");
    expect_cli_refuses("replay " + dir.file("ext.h5") + " --calibration " +
                           test::source_path("examples/factory.yaml") + " --attitude " + dir.file("a.csv") +
                           " --events " + dir.file("e.jsonl"),
                       "ext.h5");
  }
}

TEST(HostileH5, FilterTetraDoesNotWriteIsRefused) {
  TempDir dir;
  Hostile h;
  h.fletcher32_g1 = true;
  write_log(dir.file("crc.h5"), h);
  const auto log = read_gyro_log(dir.file("crc.h5"));
  ASSERT_FALSE(log.ok());
  EXPECT_NE(log.error().message.find("crc.h5: dataset 'g1': filter 3, which tetra does not read"),
            std::string::npos)
      << log.error().message;
}

// A comment with a line break would become two CSV lines, the second not a comment: refused when read.
TEST(HostileH5, CommentWithLineBreakIsRefused) {
  TempDir dir;
  Hostile h;
  h.comments = {" units=V", " two\nlines"};
  write_log(dir.file("nl.h5"), h);
  const auto log = read_gyro_log(dir.file("nl.h5"));
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.error().message,
            dir.file("nl.h5") + ": attribute 'comments' entry 2 holds a line break (a comment is one line)");
  expect_cli_refuses("convert " + dir.file("nl.h5") + " " + dir.file("out.csv"), "nl.h5");
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.csv")));
}

// Units said two ways: the attribute is the rule, and comments that contradict it are an error.
TEST(HostileH5, UnitsAttributeAndCommentsMustAgree) {
  TempDir dir;
  Hostile h;
  h.units = "V";
  h.comments = {" units=dps"};
  write_log(dir.file("units.h5"), h);
  const auto log = read_gyro_log(dir.file("units.h5"));
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.error().message,
            dir.file("units.h5") +
                ": attribute 'units' is 'V' but the comments say units=dps (the attribute "
                "and the comments must agree)");
  h.units = "dps";
  write_log(dir.file("agree.h5"), h);
  const auto agree = read_gyro_log(dir.file("agree.h5"));
  ASSERT_TRUE(agree.ok()) << agree.error().message;
  EXPECT_TRUE(agree->units_dps);
}

// Comments larger than an attribute stored in the object header (64 KiB) are written (dense attribute
// storage) and read back: the converted CSV is the same file.
TEST(HostileH5, ManyCommentLinesRoundTrip) {
  TempDir dir;
  std::string csv;
  for (int i = 0; i < 2000; ++i) csv += "# note" + std::to_string(i) + "=" + std::string(50, 'x') + "\n";
  csv += "time_s,g1\n0,0.5\n0.01,0.25\n";
  test::write_file(dir.file("many.csv"), csv);
  auto r = test::run_tetra("convert " + dir.file("many.csv") + " " + dir.file("many.h5"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  r = test::run_tetra("convert " + dir.file("many.h5") + " " + dir.file("back.csv"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(test::read_file(dir.file("back.csv")), csv);
}

// A full disk during an HDF5 write (here: a file size limit, SIGXFSZ ignored so writes fail with
// EFBIG): the command reports the failed write and exits 1 by itself; libhdf5 used to crash at exit
// closing the half-written file again. No temporary file is left.
TEST(HostileH5, FailedWriteExitsCleanly) {
  TempDir dir;
  const auto r =
      test::run_shell("cd " + dir.path().string() + " && ulimit -f 200 && trap '' XFSZ && " +
                      std::string(TETRA_BINARY) + " sim static --minutes 2 --rate-hz 200 -o full.h5");
  EXPECT_EQ(r.exit_status, 1) << r.err;
  EXPECT_NE(r.err.find("full.h5: write failed"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("full.h5")));
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) ADD_FAILURE() << entry.path();
}

// The fuzz corpus holds logs tetra wrote (seed_*: read back) and reproducers (regress_*: refused, each
// with an error naming the file). regress_flip_*: 8 bytes flipped in a log of an earlier tetra
// (variable-length strings) that crashed libhdf5 in the command reading it (exit 139), two of them in
// the global heap; the others are the hostile files above with fixed-length strings.
TEST(HostileH5, FuzzRegressionInputsEndInAValue) {
  int seeds = 0;
  int reproducers = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(test::source_path("tests/fuzz/corpus/gyro_log_h5"))) {
    const std::string name = entry.path().filename().string();
    const auto log = read_gyro_log(entry.path().string());
    if (name.rfind("seed_", 0) == 0) {
      ++seeds;
      EXPECT_TRUE(log.ok()) << log.error().message;
    } else {
      ++reproducers;
      ASSERT_FALSE(log.ok()) << name;
      EXPECT_EQ(log.error().message.rfind(entry.path().string() + ": ", 0), 0U) << log.error().message;
    }
  }
  EXPECT_GE(seeds, 4);
  EXPECT_GE(reproducers, 8);
}

// Files on which libhdf5 itself faults while it opens a dataset (tests/fuzz/libhdf5_faults/: found by the
// HDF5 fuzzer, whose in-process reading cannot survive them, so they stay out of its corpus): the checking
// child process meets the fault and the file is refused with an error naming it; nothing is read.
TEST(HostileH5, FilesOnWhichLibhdf5FaultsAreRefusedByTheCheckingChild) {
  int files = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(test::source_path("tests/fuzz/libhdf5_faults"))) {
    ++files;
    const auto log = read_gyro_log(entry.path().string());
    ASSERT_FALSE(log.ok()) << entry.path();
    EXPECT_EQ(log.error().message.rfind(entry.path().string() + ": damaged HDF5 file", 0), 0U)
        << log.error().message;
  }
  EXPECT_GE(files, 1);
}

}  // namespace
}  // namespace tetra
