// A dispersed campaign with requirements on the command line: the draws' columns, rows independent of
// --jobs, the statistics and requirements in report.md with the size plot, and a resume refused when
// other parameters are dispersed.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace tetra::test {
namespace {

std::vector<std::string> sorted_lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  std::sort(out.begin() + 1, out.end());
  return out;
}

// 1 kind × 1 gyro × 3 seeds + 3 fault-free = 6 runs of 1 min.
std::string dispersed_spec(const std::string& size_law) {
  return "scenarios: [" + source_path("examples/sim/closed_loop_calibrated.yaml") +
         "]\nduration_s: 60\nkinds: [bias]\nsizes: {bias: [0.01]}\ngyros: [1]\nonsets_s: [20]\n"
         "seeds: {first: 1, count: 3}\nfault_free: true\n"
         "dispersions:\n  seed: 5\n  unit.axis: calibration\n  reference.noise_arcsec: {uniform: [4, 6]}\n"
         "  fault.onset_s: {uniform: [0, 20]}\n  fault.size_factor: " +
         size_law +
         "\nrequirements:\n  - wrong_exclusion_rate < 1e-3 at 0.95\n  - detection_rate[bias] > 0.5 at 0.9\n";
}

TEST(CampaignDispersedCli, RowsCarryTheDrawsAndTheReportJudgesTheRequirements) {
  TempDir dir;
  write_file(dir.file("spec.yaml"), dispersed_spec("{uniform: [0.5, 2]}"));
  const auto one = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + dir.file("a") + " --jobs 1");
  ASSERT_EQ(one.exit_status, 0) << one.err;
  const auto two =
      run_tetra("campaign " + dir.file("spec.yaml") + " --out " + dir.file("b") + " --jobs 2 --no-report");
  ASSERT_EQ(two.exit_status, 0) << two.err;
  const auto rows = sorted_lines(read_file(dir.file("a") + "/runs.csv"));
  EXPECT_EQ(rows, sorted_lines(read_file(dir.file("b") + "/runs.csv")))
      << "each run's draws are a function of (seed, run) only, not of the worker";
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_NE(rows[0].find(",wrong_at_s,error,unit.axis.g1.x,"), std::string::npos) << rows[0];
  EXPECT_NE(rows[0].find(",reference.noise_arcsec,fault.onset_s,fault.size_factor"), std::string::npos);
  const auto commas = std::count(rows[0].begin(), rows[0].end(), ',');
  for (const std::string& row : rows) EXPECT_EQ(std::count(row.begin(), row.end(), ','), commas) << row;
  const std::string report = read_file(dir.file("a") + "/report.md");
  EXPECT_NE(report.find("## Statistics with confidence"), std::string::npos) << report;
  EXPECT_NE(report.find("| wrong exclusion (all runs) | 0 | 6 | 0 | [0, 0.4593] |"), std::string::npos)
      << report;  // 1 − 0.025^(1/6) = 0.4593
  EXPECT_NE(report.find("| `wrong_exclusion_rate < 1e-3 at 0.95` | 0 of 6 runs |"), std::string::npos);
  EXPECT_NE(report.find("not yet decidable | 2989 |"), std::string::npos) << report;  // 2995 − 6
  EXPECT_TRUE(std::filesystem::exists(dir.file("a") + "/detection_vs_size_bias.png"));
  // A row torn among the draws' columns is redone on resume, to the same row.
  const std::string complete = read_file(dir.file("b") + "/runs.csv");
  write_file(dir.file("b") + "/runs.csv", complete.substr(0, complete.size() - 20));
  const auto resumed =
      run_tetra("campaign " + dir.file("spec.yaml") + " --out " + dir.file("b") + " --no-report");
  ASSERT_EQ(resumed.exit_status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("5 already done"), std::string::npos) << resumed.err;
  EXPECT_EQ(sorted_lines(read_file(dir.file("b") + "/runs.csv")), rows);
  // The same folder with another parameter dispersed: other columns, refused; runs.csv untouched.
  const std::string before = read_file(dir.file("b") + "/runs.csv");
  write_file(dir.file("spec.yaml"), dispersed_spec("{uniform: [0.5, 2]}\n  unit.bias_V: calibration"));
  const auto other =
      run_tetra("campaign " + dir.file("spec.yaml") + " --out " + dir.file("b") + " --no-report");
  EXPECT_EQ(other.exit_status, 2) << other.err;
  EXPECT_NE(other.err.find("this folder holds a campaign of another spec"), std::string::npos) << other.err;
  EXPECT_EQ(read_file(dir.file("b") + "/runs.csv"), before);
}

}  // namespace
}  // namespace tetra::test
