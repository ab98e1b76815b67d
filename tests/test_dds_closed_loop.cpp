// The closed loop over DDS: `tetra sim --closed-loop --dds` against a running `tetra fusion`.
// Lockstep gives the in-process loop's numbers bit for bit; real time at 100 Hz holds the pointing.
// Each test uses its own domain id and kills what it starts; nothing asserts on elapsed time.

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <string>
#include <thread>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

const bool kLoopback = use_loopback_dds();

//! A nadir closed-loop scenario on the seed's unit (written to a file the service reads too), a
//! gyro-2 bias step at half time, and the service's configuration at the same rate.
struct LoopFiles {
  TempDir dir;
  std::string scenario;
  std::string config;
  LoopFiles(double rate_hz, double duration_s, double speed) {
    Calibration cal = seed_as_built_unit();
    cal.unit = "tetra-loop";
    EXPECT_TRUE(write_calibration(dir.file("cal.yaml"), cal).ok());
    scenario = dir.file("loop.yaml");
    write_file(scenario, "scenario: orbit\nduration_s: " + std::to_string(duration_s) +
                             "\nrate_hz: " + std::to_string(rate_hz) + "\nunit: cal.yaml\n" +
                             "reference: {rate_hz: 1, noise_arcsec: 5}\nfaults: [\"gyro=2,kind=bias,at=" +
                             std::to_string(duration_s / 2) + ",size=0.01\"]\n" +
                             "closed_loop: {controller: {bandwidth_hz: 0.05}, pointing: {mode: nadir}, "
                             "pointing_bound_deg: 0.05}\n");
    config = dir.file("fusion.yaml");
    write_file(config, "unit: tetra-loop\ncalibration: cal.yaml\nsample_rate_hz: " + std::to_string(rate_hz) +
                           "\nspeed: " + std::to_string(speed) +
                           "\nmax_latency_s: 0.05\nhealth_period_s: 0.2\n");
  }
};

TEST(DdsClosedLoop, LockstepEqualsInProcessBitForBit) {
  const int domain = 211;
  LoopFiles files(10.0, 120.0, 1.0);
  const auto local =
      run_tetra("sim " + files.scenario + " --closed-loop --pointing " + files.dir.file("local.csv"));
  ASSERT_EQ(local.exit_status, 0) << local.err;
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", std::to_string(domain)},
                      files.dir.file("fusion.log"));
  const auto wire = run_tetra("sim " + files.scenario + " --closed-loop --dds --domain " +
                              std::to_string(domain) + " --pointing " + files.dir.file("wire.csv"));
  ASSERT_EQ(wire.exit_status, 0) << wire.err << wire.out << read_file(files.dir.file("fusion.log"));
  EXPECT_EQ(wire.out.find("without their Attitude"), std::string::npos) << wire.out;
  const std::string a = read_file(files.dir.file("local.csv"));
  const std::string b = read_file(files.dir.file("wire.csv"));
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "lockstep over DDS differs from the in-process loop";
  EXPECT_EQ(fusion.signal_and_wait(SIGTERM), 0);
}

// Real time at 100 Hz: the controller steers with the newest Attitude (about one epoch old). The bound
// is the scenario's 0.05°; the measured maximum is about 0.0003° (a margin of two orders of magnitude,
// for a loaded machine where Attitudes come late and the controller holds its command).
TEST(DdsClosedLoop, RealTimeAt100HzHoldsThePointingBound) {
  const int domain = 212;
  LoopFiles files(100.0, 20.0, 1.0);
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", std::to_string(domain)},
                      files.dir.file("fusion.log"));
  const std::string summary = files.dir.file("summary.json");
  const auto run = run_tetra("sim " + files.scenario + " --closed-loop --dds --real-time --domain " +
                             std::to_string(domain) + " --summary " + summary);
  ASSERT_EQ(run.exit_status, 0) << run.err << run.out << read_file(files.dir.file("fusion.log"));
  const std::string json = read_file(summary);
  const auto at = json.find("\"max_deg\": ");
  ASSERT_NE(at, std::string::npos) << json;
  const double max_deg = std::stod(json.substr(at + 11));
  EXPECT_LT(max_deg, 0.05) << run.out;
  EXPECT_NE(json.find("\"recovered\": true"), std::string::npos) << json;
  EXPECT_EQ(fusion.signal_and_wait(SIGTERM), 0);
}

// One service per unit on a domain: a second `tetra fusion` for a unit already served hears the first's
// Health, refuses to start (exit 1, naming the unit and the domain) and writes nothing, so the first goes
// on serving and a lockstep run against it still equals the in-process loop byte for byte.
TEST(DdsClosedLoop, SecondServiceOfTheUnitIsRefused) {
  const int domain = 213;
  LoopFiles files(10.0, 60.0, 1.0);
  TetraProcess first({"fusion", "--config", files.config, "--domain", std::to_string(domain)},
                     files.dir.file("first.log"));
  // Serving once it says so (after its own probe for another service): up to 30 s on a loaded machine.
  for (int i = 0; i < 600 && read_file(files.dir.file("first.log")).find("running") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_NE(read_file(files.dir.file("first.log")).find("running"), std::string::npos);
  TetraProcess second({"fusion", "--config", files.config, "--domain", std::to_string(domain)},
                      files.dir.file("second.log"));
  EXPECT_EQ(second.wait_exit(), 1);
  const std::string refused = read_file(files.dir.file("second.log"));
  EXPECT_NE(refused.find("another fusion service for unit 'tetra-loop' is running on domain " +
                         std::to_string(domain)),
            std::string::npos)
      << refused;
  EXPECT_EQ(refused.find("running, "), std::string::npos) << refused;  // it never served
  const auto local =
      run_tetra("sim " + files.scenario + " --closed-loop --pointing " + files.dir.file("local.csv"));
  ASSERT_EQ(local.exit_status, 0) << local.err;
  const auto wire = run_tetra("sim " + files.scenario + " --closed-loop --dds --domain " +
                              std::to_string(domain) + " --pointing " + files.dir.file("wire.csv"));
  ASSERT_EQ(wire.exit_status, 0) << wire.err << wire.out << read_file(files.dir.file("first.log"));
  EXPECT_TRUE(read_file(files.dir.file("local.csv")) == read_file(files.dir.file("wire.csv")));
  EXPECT_EQ(first.signal_and_wait(SIGTERM), 0);
}

}  // namespace
}  // namespace tetra::test
