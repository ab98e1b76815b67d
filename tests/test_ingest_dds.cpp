// `tetra ingest` from a pseudo-terminal (openpty, set up by ingest with termios: baud, even parity) into
// `tetra record` over loopback DDS: every well-formed line arrives, malformed ones are counted and reported
// and never stop the run. The line protocol's parser alone: whole lines, split lines, refusals.
#include <fcntl.h>
#include <pty.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <span>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/sample_parser.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

const bool kIngestLoopback = use_loopback_dds();

std::vector<RawGyroSample> feed_all(LineProtocolParser& p, const std::string& text) {
  std::vector<RawGyroSample> out;
  p.feed(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), out);
  p.flush(out);
  return out;
}

TEST(LineProtocol, OneGyroOrAllGyrosPerLine) {
  LineProtocolParser p(4);
  const auto s = feed_all(p, "# comment\n\n0.5,all,1,2,3,nan\r\n0.51,3,0.25\n0.52,2,-1e-3");
  ASSERT_EQ(s.size(), 6U);
  EXPECT_EQ(s[0].gyro, 1);
  EXPECT_EQ(s[3].gyro, 4);
  EXPECT_TRUE(std::isnan(s[3].raw));
  EXPECT_EQ(s[4].gyro, 3);
  EXPECT_EQ(s[4].raw, 0.25);
  EXPECT_EQ(s[5].time_s, 0.52);  // the last line without its newline: flush() completes it
  EXPECT_EQ(p.accepted(), 3U);
  EXPECT_EQ(p.malformed(), 0U);
}

TEST(LineProtocol, MalformedLinesAreCountedWithTheirReason) {
  LineProtocolParser p(4);
  const auto s = feed_all(p,
                          "x,1,2\n"        // time
                          "1,5,0.1\n"      // gyro out of range
                          "1,all,1,2,3\n"  // too few
                          "1,2,abc\n"      // raw
                          "1,2,inf\n"      // raw
                          "1,2\n"          // too few fields
                          "1,1.5,0\n"      // gyro not whole
                          "2,1,0.5\n");    // good
  EXPECT_EQ(s.size(), 1U);
  EXPECT_EQ(p.malformed(), 7U);
  EXPECT_EQ(p.last_problem(), "line 7: gyro must be 1..4 or 'all'");
  LineProtocolParser q(1);
  const std::string longest(LineProtocolParser::kMaxLineBytes + 10, '1');
  (void)feed_all(q, longest + "\n1,1,2\n");
  EXPECT_EQ(q.malformed(), 1U);
  EXPECT_EQ(q.accepted(), 1U);
}

TEST(IngestDds, PseudoTerminalLinesReachTheWireMalformedCounted) {
  TempDir dir;
  int master = -1;
  int slave = -1;
  ASSERT_EQ(::openpty(&master, &slave, nullptr, nullptr, nullptr), 0);
  // Not inherited by the processes started below: ingest must see the hang-up when the test closes them.
  ASSERT_EQ(::fcntl(master, F_SETFD, FD_CLOEXEC), 0);
  ASSERT_EQ(::fcntl(slave, F_SETFD, FD_CLOEXEC), 0);
  termios raw{};
  ASSERT_EQ(::tcgetattr(slave, &raw), 0);
  ::cfmakeraw(&raw);  // no echo back into the master before ingest sets the port up
  ASSERT_EQ(::tcsetattr(slave, TCSANOW, &raw), 0);
  const std::string device = ::ttyname(slave);
  const std::string d = "174";
  TetraProcess record({"record", "--unit", "lab-2", "--gyros", "4", "--rate", "100", "--domain", d, "-o",
                       dir.file("rec.csv"), "--until-idle"},
                      dir.file("record.log"));
  TetraProcess ingest({"ingest", "--serial", device, "--baud", "115200", "--parity", "even", "--unit",
                       "lab-2", "--gyros", "4", "--domain", d, "--quiet", "--wait-readers", "1"},
                      dir.file("ingest.log"));
  // ingest reads the terminal only once the recorder's reader has matched (a loaded machine discovers late:
  // without the wait, the first 16 epochs reached no reader).
  std::string text;
  for (int k = 0; k < 200; ++k) {
    const std::string t = std::to_string(k * 0.01);
    if (k % 2 == 0) {
      text += t + ",all,0.1,0.2,0.3,0.4\n";
    } else {
      for (int g = 1; g <= 4; ++g) text += t + "," + std::to_string(g) + ",0." + std::to_string(g) + "\n";
    }
    if (k == 50) text += "garbage line\n";
    if (k == 120) text += t + ",9,1\n";
  }
  // Blocking writes: the pseudo-terminal holds what ingest has not read yet (flow control, nothing lost).
  for (std::size_t off = 0; off < text.size();) {
    const ssize_t n = ::write(master, text.data() + off, std::min<std::size_t>(512, text.size() - off));
    ASSERT_GT(n, 0);
    off += static_cast<std::size_t>(n);
  }
  // Until ingest has read everything (nothing left in the terminal's input queue), then hang up.
  for (int waited = 0; waited < 2000; ++waited) {
    int pending = 0;
    ASSERT_EQ(::ioctl(slave, FIONREAD, &pending), 0);
    if (pending == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ::close(master);
  ::close(slave);
  ASSERT_EQ(ingest.wait_exit(), 0) << read_file(dir.file("ingest.log"));
  ASSERT_EQ(record.wait_exit(), 0) << read_file(dir.file("record.log"));
  const std::string out = read_file(dir.file("ingest.log"));
  EXPECT_NE(out.find("lines: 500 accepted, 2 malformed (last: line 303: gyro must be 1..4 or 'all')"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("samples published: 800"), std::string::npos) << out;
  // 200 epochs of 4 gyros recorded: every line arrived.
  std::istringstream rec(read_file(dir.file("rec.csv")));
  std::size_t rows = 0;
  for (std::string line; std::getline(rec, line);) rows += !line.empty() && line[0] != '#' ? 1 : 0;
  EXPECT_EQ(rows, 201U) << read_file(dir.file("record.log"));  // the header and 200 epochs
}

// A source faster than real time (a file of 800 s at 100 Hz, read as fast as it comes: about 2 s) into a
// recorder paused 0.2 s five times: ingest's writer keeps every sample until the recorder has it (it kept
// 4,096 a gyro), the recorder's reader keeps every sample until taken (it kept 4,096) and the recorder
// hands the samples on in time order across takes (a take gives one gyro's after another's: the later
// gyros became time outliers: 1,597 of 40,000 epochs lost at full speed with no pause), and every line
// is recorded as it was written.
TEST(IngestDds, ARecorderPausedBehindASourceFasterThanRealTimeLosesNothing) {
  TempDir dir;
  std::string text;
  const auto g4_of = [](int k) { return 0.001 * (k % 1000); };
  constexpr int kEpochs = 80000;
  for (int k = 0; k < kEpochs; ++k) {
    text += std::to_string(k * 0.01) + ",all,0.1,0.2,0.3," + std::to_string(g4_of(k)) + "\n";
  }
  write_file(dir.file("in.txt"), text);
  const std::string d = "175";
  TetraProcess record({"record", "--unit", "lab-3", "--gyros", "4", "--rate", "100", "--domain", d, "-o",
                       dir.file("rec.csv"), "--until-idle"},
                      dir.file("record.log"));
  std::atomic<bool> done{false};
  std::thread pauser([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the reader found, samples flowing
    for (int k = 0; k < 5 && !done; ++k) {
      record.signal(SIGSTOP);
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      record.signal(SIGCONT);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  const auto ingest = run_tetra("ingest --unit lab-3 --gyros 4 --rate-hz 100 --wait-readers 1 --domain " + d +
                                " < " + dir.file("in.txt"));
  done = true;
  pauser.join();
  record.signal(SIGCONT);
  ASSERT_EQ(ingest.exit_status, 0) << ingest.err;
  EXPECT_NE(ingest.out.find("samples published: 320000"), std::string::npos) << ingest.out;
  ASSERT_EQ(record.wait_exit(), 0) << read_file(dir.file("record.log"));
  const std::string log = read_file(dir.file("record.log"));
  EXPECT_NE(log.find("80000 epochs of unit lab-3"), std::string::npos) << log;
  EXPECT_NE(log.find("gap 0, time outlier 0"), std::string::npos) << log;
  std::istringstream rec(read_file(dir.file("rec.csv")));
  std::size_t k = 0;
  std::size_t wrong = 0;
  for (std::string line; std::getline(rec, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    double v[5] = {};
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4]) != 5 ||
        std::abs(v[0] - static_cast<double>(k) * 0.01) > 1e-6 || v[1] != 0.1 || v[2] != 0.2 || v[3] != 0.3 ||
        std::abs(v[4] - g4_of(static_cast<int>(k))) > 1e-9) {
      if (wrong++ == 0) ADD_FAILURE() << "row " << k << ": " << line << "\n" << log;
    }
    ++k;
  }
  EXPECT_EQ(k, static_cast<std::size_t>(kEpochs));
  EXPECT_EQ(wrong, 0U) << "rows recorded otherwise than written";
}

}  // namespace
}  // namespace tetra::test
