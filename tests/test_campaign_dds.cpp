// tetra campaign with `target: dds`: each run against its own `tetra fusion` service over DDS
// in lockstep gives the very rows of the in-process campaign — every column, compared as text: the FDI
// verdict (outcome, isolated gyro, delays, false alarms, wrong exclusions, read from the service's FdiEvent
// topic) and the numbers (knowledge error, sigma, pointing), since the service runs the same pipeline on
// the same epochs from the same initial attitude. Closed loop on domain 216, open loop on 217; nothing
// asserts on elapsed time.

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

const bool kLoopback = use_loopback_dds();

std::vector<std::string> sorted_lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  std::sort(out.begin(), out.end());
  return out;
}

//! Runs the campaign. A run over DDS fails (and the campaign exits 1) when a stall of the machine
//! outlasted the service's limits (a sample later than 0.5 s, an Attitude later than 2 s): the campaign
//! is resumable, so it is run once more (it redoes only the failed runs; the rows are then compared).
CommandResult run_campaign(const std::string& spec, const std::string& out) {
  auto result = run_tetra("campaign " + spec + " --out " + out + " --jobs 2 --no-report");
  if (result.exit_status == 1 && result.err.find("a run failed") != std::string::npos)
    result = run_tetra("campaign " + spec + " --out " + out + " --jobs 2 --no-report");
  return result;
}

void expect_same_rows(const TempDir& dir, const std::string& spec_body, int domain) {
  write_file(dir.file("local.yaml"), spec_body);
  write_file(dir.file("wire.yaml"), spec_body + "target: dds\ndomain: " + std::to_string(domain) + "\n");
  const auto local = run_campaign(dir.file("local.yaml"), dir.file("local"));
  ASSERT_EQ(local.exit_status, 0) << local.err;
  const auto wire = run_campaign(dir.file("wire.yaml"), dir.file("wire"));
  ASSERT_EQ(wire.exit_status, 0) << wire.err;
  EXPECT_NE(wire.err.find("fusion services over DDS, domain " + std::to_string(domain)), std::string::npos)
      << wire.err;
  const auto a = sorted_lines(read_file(dir.file("local/runs.csv")));
  const auto b = sorted_lines(read_file(dir.file("wire/runs.csv")));
  ASSERT_GT(a.size(), 2u);
  EXPECT_EQ(a, b) << "the DDS campaign's rows differ from the in-process campaign's";
}

// 2 kinds × 2 gyros × 1 onset × 1 seed + 1 fault-free = 5 runs of 1 min (10 Hz, 600 epochs each).
TEST(CampaignDds, ClosedLoopRowsEqualTheInProcessCampaign) {
  TempDir dir;
  expect_same_rows(dir,
                   "scenarios: [" + source_path("examples/sim/closed_loop_nadir.yaml") +
                       "]\nduration_s: 60\nkinds: [bias, stuck]\nsizes: {bias: [0.01]}\ngyros: [1, 4]\n"
                       "onsets_s: [30]\nseeds: [1]\nfault_free: true\n",
                   216);
}

// The built-in orbit, open loop: a stuck gyro and a dropout (a gyro that stops: the service holds its
// epochs until it declares the gyro absent, and the pipeline gets the same epochs as in process).
TEST(CampaignDds, OpenLoopRowsEqualTheInProcessCampaign) {
  TempDir dir;
  expect_same_rows(dir,
                   "loop: open\nscenarios: [orbit]\nduration_s: 60\nkinds: [stuck, dropout]\ngyros: [3]\n"
                   "onsets_s: [30]\nseeds: [2]\n",
                   217);
}

}  // namespace
}  // namespace tetra::test
