// `tetra play` into `tetra fusion` (docs/dds.md, "Playing a log"): real processes on loopback DDS, each test
// on its own domain. A faulted log played in lockstep gives the service exactly the epochs `tetra replay`
// sees: the same events and, for every attitude the recorder received, the same numbers bit for bit. Paced,
// the service sees the same epochs when nothing is lost; the test states its bound below. No timing is
// asserted.
#include <atomic>
#include <chrono>
#include <csignal>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

const bool kPlayLoopback = use_loopback_dds();

struct PlayFiles {
  TempDir dir;
  std::string config;
  std::string log;
  PlayFiles() {
    EXPECT_EQ(run_tetra("sim --write-unit " + dir.file("cal.yaml")).exit_status, 0);
    std::string cal = read_file(dir.file("cal.yaml"));
    config = dir.file("fusion.yaml");
    write_file(config,
               "unit: lab-1\ncalibration: cal.yaml\nsample_rate_hz: 100\nspeed: 1\nmax_latency_s: 0.05\n"
               "health_period_s: 0.2\n");
    log = dir.file("faulted.csv");
    // 100 Hz, 15 s of orbit motion without a reference, gyro 2 stuck from 5 s.
    const auto sim = run_tetra(
        "sim orbit --rate-hz 100 --minutes 0.25 --reference-hz 0 "
        "--fault gyro=2,kind=stuck,at=5 -o " +
        log);
    EXPECT_EQ(sim.exit_status, 0) << sim.err;
  }
};

//! Events without the service's reports on its gyro streams (all silent / samples back): a log has none.
std::string without_stream_events(const std::string& events) {
  std::istringstream in(events);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    if (line.find("all gyros silent") == std::string::npos &&
        line.find("gyro samples back") == std::string::npos)
      out += line + '\n';
  }
  return out;
}

//! Attitude rows (time → the rest of the line) without comment and header lines.
std::map<std::string, std::string> attitude_rows(const std::string& text) {
  std::map<std::string, std::string> rows;
  std::istringstream in(text);
  bool header = true;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    const auto comma = line.find(',');
    // mode, gyros and sigmas as the service sends them; the bias columns after them are not on the wire.
    std::size_t end = comma;
    for (int commas = 0; end < line.size(); ++end) {
      if (line[end] == ',' && ++commas == 14) break;
    }
    rows[line.substr(0, comma)] = line.substr(comma, end - comma);
  }
  return rows;
}

//! Rows of `expected` that `got` lacks or holds otherwise, plus rows `got` has beyond them.
std::size_t rows_differing(const std::map<std::string, std::string>& got,
                           const std::map<std::string, std::string>& expected) {
  std::size_t n = 0;
  for (const auto& [time, rest] : expected) {
    const auto it = got.find(time);
    n += it == got.end() || it->second != rest ? 1 : 0;
  }
  for (const auto& [time, rest] : got) n += expected.count(time) == 0 ? 1 : 0;
  return n;
}

void play_and_compare(const std::string& speed, int domain) {
  PlayFiles f;
  const auto replay =
      run_tetra("replay " + f.log + " --calibration " + f.dir.file("cal.yaml") + " --attitude " +
                f.dir.file("replay_att.csv") + " --events " + f.dir.file("replay_ev.jsonl"));
  ASSERT_EQ(replay.exit_status, 0) << replay.err;
  const std::string d = std::to_string(domain);
  TetraProcess fusion({"fusion", "--config", f.config, "--domain", d}, f.dir.file("fusion.log"));
  TetraProcess record(
      {"record", "--config", f.config, "--domain", d, "-o", f.dir.file("rec.csv"), "--attitude",
       f.dir.file("dds_att.csv"), "--events", f.dir.file("dds_ev.jsonl"), "--until-idle"},
      f.dir.file("record.log"));
  const auto play =
      run_tetra("play " + f.log + " --unit lab-1 --speed " + speed + " --wait-readers 2 --domain " + d);
  ASSERT_EQ(play.exit_status, 0) << play.err << play.out << read_file(f.dir.file("fusion.log"));
  EXPECT_NE(play.out.find("epochs published: 1500"), std::string::npos) << play.out;
  ASSERT_EQ(record.wait_exit(), 0) << read_file(f.dir.file("record.log"));
  const std::string expected = read_file(f.dir.file("replay_ev.jsonl"));
  EXPECT_NE(expected.find("\"isolated\""), std::string::npos) << expected;
  EXPECT_EQ(without_stream_events(read_file(f.dir.file("dds_ev.jsonl"))), expected);
  // Attitude is keep-last 1 for readers (the service's writer keeps 128): the recorder may miss some under
  // heavy load; what it did receive equals replay's.
  const auto dds_rows = attitude_rows(read_file(f.dir.file("dds_att.csv")));
  const auto replay_rows = attitude_rows(read_file(f.dir.file("replay_att.csv")));
  ASSERT_EQ(replay_rows.size(), 1500U);
  EXPECT_GE(dds_rows.size(), 1425U);  // at least 95 % received (the end-to-end DDS tests' bound)
  for (const auto& [time, rest] : dds_rows) {
    const auto it = replay_rows.find(time);
    ASSERT_NE(it, replay_rows.end()) << "an epoch replay did not see: t = " << time;
    ASSERT_EQ(rest, it->second) << "t = " << time;
  }
}

// Lockstep (--speed max): each epoch waits for the service's attitude of it.
TEST(PlayDds, FaultedLogInLockstepGivesReplaysEventsAndAttitudes) {
  play_and_compare("max", 171);
}

// Paced at 10 times the log's pace: with no sample lost (reliable, keep-all at 1 kHz wall rate) the
// service assembles the same epochs, so the bound is the same: equal events, equal attitudes.
TEST(PlayDds, FaultedLogPacedGivesReplaysEventsAndAttitudes) {
  play_and_compare("10", 172);
}

// Lockstep into the service with the recorder paused (SIGSTOP) 0.2 s at a time, five times mid-play:
// the player's samples wait for it (KEEP_ALL) and the service's attitudes are kept for it, so the
// recorded log replays to replay's 1,500 attitudes bit for bit and the recorded attitudes are all 1,500
// of them. Before (the player's writer keeping 64 samples per gyro, the service's Attitude writer 1),
// both differed: the recorded log replayed to LOST from its first epoch.
TEST(PlayDds, LockstepWithTheRecorderPausedLosesNothing) {
  PlayFiles f;
  const auto replay =
      run_tetra("replay " + f.log + " --calibration " + f.dir.file("cal.yaml") + " --attitude " +
                f.dir.file("replay_att.csv") + " --events " + f.dir.file("replay_ev.jsonl"));
  ASSERT_EQ(replay.exit_status, 0) << replay.err;
  const std::string d = "174";
  TetraProcess fusion({"fusion", "--config", f.config, "--domain", d}, f.dir.file("fusion.log"));
  TetraProcess record({"record", "--config", f.config, "--domain", d, "-o", f.dir.file("rec.csv"),
                       "--attitude", f.dir.file("dds_att.csv"), "--until-idle"},
                      f.dir.file("record.log"));
  std::atomic<bool> done{false};
  std::thread pauser([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // readers found, playing
    for (int k = 0; k < 5 && !done; ++k) {
      record.signal(SIGSTOP);
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      record.signal(SIGCONT);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
  });
  const auto play = run_tetra("play " + f.log + " --unit lab-1 --speed max --wait-readers 2 --domain " + d);
  done = true;
  pauser.join();
  record.signal(SIGCONT);
  ASSERT_EQ(play.exit_status, 0) << play.err << play.out;
  ASSERT_EQ(record.wait_exit(), 0) << read_file(f.dir.file("record.log"));
  const auto replay_rows = attitude_rows(read_file(f.dir.file("replay_att.csv")));
  ASSERT_EQ(replay_rows.size(), 1500U);
  EXPECT_EQ(rows_differing(attitude_rows(read_file(f.dir.file("dds_att.csv"))), replay_rows), 0U)
      << "recorded attitudes missing or different";
  const auto again =
      run_tetra("replay " + f.dir.file("rec.csv") + " --calibration " + f.dir.file("cal.yaml") +
                " --attitude " + f.dir.file("again_att.csv") + " --events " + f.dir.file("again_ev.jsonl"));
  ASSERT_EQ(again.exit_status, 0) << again.err;
  EXPECT_EQ(rows_differing(attitude_rows(read_file(f.dir.file("again_att.csv"))), replay_rows), 0U)
      << "the recorded log's epochs replay otherwise";
}

TEST(PlayCli, BadInputsAreOneLineExitTwo) {
  TempDir dir;
  write_file(dir.file("dps.csv"), "# units=dps\ntime_s,g1,g2,g3\n0,1,2,3\n");
  auto r = run_tetra("play " + dir.file("dps.csv") + " --domain 173 --wait-timeout 1");
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find("units=dps"), std::string::npos) << r.err;
  r = run_tetra("play " + dir.file("dps.csv") + " --speed fast");
  EXPECT_EQ(r.exit_status, 2) << r.err;
  write_file(dir.file("v.csv"), "time_s,g1,g2,g3\n0,1,2,3\n");
  r = run_tetra("play " + dir.file("v.csv") + " --start 5 --domain 173");
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find("no epoch within --start/--end"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace tetra::test
