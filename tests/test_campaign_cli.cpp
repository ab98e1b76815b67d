// tetra campaign on the command line: rows, resuming after an interruption, the report,
// and errors naming the spec's line.

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace tetra::test {
namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// 2 kinds × 2 gyros × 1 onset × 2 seeds + 2 fault-free = 10 runs of 2 min.
void write_spec(const TempDir& dir) {
  write_file(dir.file("spec.yaml"), "scenarios: [" + source_path("examples/sim/closed_loop_nadir.yaml") +
                                        "]\nduration_s: 120\nkinds: [bias, stuck]\nsizes: {bias: [0.01]}\n"
                                        "gyros: [1, 4]\nonsets_s: [60]\nseeds: [1, 2]\nfault_free: true\n");
}

TEST(CampaignCli, RunsResumesAndReports) {
  TempDir dir;
  write_spec(dir);
  const std::string out = dir.file("out");
  const auto first = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --jobs 2");
  ASSERT_EQ(first.exit_status, 0) << first.err;
  const std::string runs = read_file(out + "/runs.csv");
  auto rows = lines_of(runs);
  ASSERT_EQ(rows.size(), 11u) << runs;  // header + 10
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const bool fault_free = rows[i].find(",none,") != std::string::npos;
    EXPECT_NE(rows[i].find(fault_free ? ",none," : ",right,"), std::string::npos) << rows[i];
  }
  const std::string report = read_file(out + "/report.md");
  EXPECT_NE(report.find("10 runs"), std::string::npos) << report;  // every row read back
  EXPECT_NE(report.find("## Wrong exclusions\n\nNone."), std::string::npos) << report;

  // Interrupted: the last row torn in the middle and another missing. Resuming redoes exactly those.
  std::string cut;
  for (std::size_t i = 0; i + 2 < rows.size(); ++i) cut += rows[i] + "\n";
  cut += rows.back().substr(0, rows.back().size() / 2);
  write_file(out + "/runs.csv", cut);
  const auto again =
      run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --jobs 1 --no-report");
  ASSERT_EQ(again.exit_status, 0) << again.err;
  EXPECT_NE(again.err.find("8 already done"), std::string::npos) << again.err;
  auto resumed = lines_of(read_file(out + "/runs.csv"));
  std::sort(rows.begin() + 1, rows.end());
  std::sort(resumed.begin() + 1, resumed.end());
  EXPECT_EQ(resumed, rows) << "the resumed campaign has the same rows (runs are deterministic per seed)";
}

// `--run K` runs one run again, alone, with the same draws: its row is runs.csv's, and `--events` writes
// its decisions with their ledger rows (why it ended as it did). A run the campaign does not have is refused.
TEST(CampaignCli, OneRunAgainGivesItsRowAndItsEvents) {
  TempDir dir;
  write_spec(dir);
  const std::string out = dir.file("out");
  ASSERT_EQ(
      run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --jobs 2 --no-report").exit_status,
      0);
  std::string row3;
  for (const std::string& line : lines_of(read_file(out + "/runs.csv")))
    if (line.rfind("3,", 0) == 0) row3 = line;
  ASSERT_FALSE(row3.empty());
  const auto again =
      run_tetra("campaign " + dir.file("spec.yaml") + " --run 3 --events " + dir.file("ev.jsonl"));
  ASSERT_EQ(again.exit_status, 0) << again.err;
  const auto printed = lines_of(again.out);
  ASSERT_EQ(printed.size(), 2u) << again.out;
  EXPECT_EQ(printed[1], row3);
  const auto events = lines_of(read_file(dir.file("ev.jsonl")));
  ASSERT_FALSE(events.empty());
  bool isolated = false;
  for (const std::string& e : events) {
    EXPECT_EQ(e.front(), '{') << e;
    if (e.find("\"event\": \"isolated\"") != std::string::npos) {
      isolated = true;
      EXPECT_NE(e.find("\"ledger\": [{"), std::string::npos) << e;
    }
  }
  EXPECT_TRUE(isolated) << read_file(dir.file("ev.jsonl"));
  const auto beyond = run_tetra("campaign " + dir.file("spec.yaml") + " --run 10");
  EXPECT_EQ(beyond.exit_status, 2) << beyond.err;
  EXPECT_NE(beyond.err.find("runs 0 to 9"), std::string::npos) << beyond.err;
  const auto no_run = run_tetra("campaign " + dir.file("spec.yaml") + " --events " + dir.file("x.jsonl"));
  EXPECT_EQ(no_run.exit_status, 2) << no_run.err;
  EXPECT_NE(no_run.err.find("--events needs --run"), std::string::npos) << no_run.err;
}

// Open loop (`loop: open`): the built-in orbit and slews scenarios' own motion, nothing steering. The faults
// are isolated as in closed loop; the pointing columns are empty and the report says why.
TEST(CampaignCli, OpenLoopCampaign) {
  TempDir dir;
  write_file(dir.file("spec.yaml"),
             "loop: open\nscenarios: [orbit, slews]\nduration_s: 120\nkinds: [bias, stuck]\n"
             "sizes: {bias: [0.01]}\ngyros: [2]\nonsets_s: [60]\nseeds: [1, 2]\nfault_free: true\n");
  const std::string out = dir.file("out");
  const auto run = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --jobs 2");
  ASSERT_EQ(run.exit_status, 0) << run.err;
  EXPECT_NE(run.err.find("open loop"), std::string::npos) << run.err;
  const auto rows = lines_of(read_file(out + "/runs.csv"));
  ASSERT_EQ(rows.size(), 13u);  // header + 2 scenarios × (2 fault-free + 2 kinds × 2 seeds)
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const bool fault_free = rows[i].find(",none,") != std::string::npos;
    EXPECT_NE(rows[i].find(fault_free ? ",none," : ",right,2,"), std::string::npos) << rows[i];
    // No pointing: the eight pointing and wheel columns before the last two are empty.
    EXPECT_NE(rows[i].find(",,,,,,,,"), std::string::npos) << rows[i];
  }
  const std::string report = read_file(out + "/report.md");
  EXPECT_NE(report.find("open loop: nothing steers"), std::string::npos) << report;
  EXPECT_NE(report.find("## Wrong exclusions\n\nNone."), std::string::npos) << report;
}

TEST(CampaignCli, BadSpecNamesTheLine) {
  TempDir dir;
  write_file(dir.file("spec.yaml"),
             "scenarios: [" + source_path("examples/sim/closed_loop_nadir.yaml") +
                 "]\nkinds: [stuck, melted]\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\n");
  const auto bad = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + dir.file("out"));
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_NE(bad.err.find("spec.yaml:2"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("melted"), std::string::npos) << bad.err;
  // A scenario without a closed_loop section in a closed-loop campaign; a domain without target dds.
  write_file(dir.file("open.yaml"),
             "scenarios: [orbit]\nkinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\n");
  const auto no_loop = run_tetra("campaign " + dir.file("open.yaml") + " --out " + dir.file("out"));
  EXPECT_EQ(no_loop.exit_status, 2);
  EXPECT_NE(no_loop.err.find("open.yaml:1"), std::string::npos) << no_loop.err;
  EXPECT_NE(no_loop.err.find("loop: open"), std::string::npos) << no_loop.err;
  write_file(dir.file("domain.yaml"),
             "loop: open\nscenarios: [orbit]\nkinds: [stuck]\ngyros: [1]\n"
             "onsets_s: [60]\nseeds: [1]\ndomain: 3\n");
  const auto domain = run_tetra("campaign " + dir.file("domain.yaml") + " --out " + dir.file("out"));
  EXPECT_EQ(domain.exit_status, 2);
  EXPECT_NE(domain.err.find("domain.yaml:7"), std::string::npos) << domain.err;
  const auto open_loop = run_tetra("sim orbit --closed-loop");
  EXPECT_EQ(open_loop.exit_status, 2) << open_loop.err;
  EXPECT_NE(open_loop.err.find("closed_loop"), std::string::npos) << open_loop.err;
}

}  // namespace
}  // namespace tetra::test
