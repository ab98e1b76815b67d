// What a newcomer following the docs meets on the command line: `--fault` against a scenario file's
// faults, the built-in unit as a file (examples/seed_unit.yaml), the shipped service configuration, a
// readers timeout that names the refused QoS, and a campaign stopped by a signal (no process left
// behind, resumed by the same command). DDS on domains 226–228; nothing asserts on elapsed time.

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "test_support.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

const bool kLoopback = use_loopback_dds();

//! The `fault=` metadata lines of a simulated log (one per fault the run injected).
std::vector<std::string> fault_lines(const std::string& log_path) {
  std::vector<std::string> out;
  std::istringstream in(read_file(log_path));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("# fault=", 0) != 0) continue;
    std::string spec = line.substr(8);  // written with ';' between the fields
    for (char& c : spec) c = c == ';' ? ',' : c;
    out.push_back(spec);
  }
  return out;
}

//! The lines of a YAML file that are not comments.
std::string without_comments(const std::string& path) {
  std::istringstream in(read_file(path));
  std::string out;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind('#', 0) != 0) out += line + "\n";
  }
  return out;
}

//! Polls `done` every 50 ms for at most `limit` (a bound for a stalled machine, not a measurement).
template <class F>
bool eventually(F done, std::chrono::seconds limit = std::chrono::seconds(60)) {
  const auto give_up = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < give_up) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

//! Processes whose command line mentions `text` (the campaign's output folder is in every service's).
int processes_mentioning(const std::string& text) {
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(entry.path() / "cmdline");
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (char& c : cmdline) c = c == '\0' ? ' ' : c;
    if (cmdline.find(text) != std::string::npos && cmdline.find("test_newcomer_cli") == std::string::npos)
      ++n;
  }
  return n;
}

TEST(SimCli, FaultOnTheCommandLineReplacesTheScenarioFilesFaultsAndAddFaultAdds) {
  TempDir dir;
  write_file(dir.file("s.yaml"),
             "scenario: orbit\nduration_s: 60\nfaults: [\"gyro=2,kind=bias,at=10,size=0.01\"]\n");
  const auto own = run_tetra("sim " + dir.file("s.yaml") + " -o " + dir.file("a.csv"));
  ASSERT_EQ(own.exit_status, 0) << own.err;
  EXPECT_EQ(fault_lines(dir.file("a.csv")), std::vector<std::string>{"gyro=2,kind=bias,at=10,size=0.01"});

  const auto replaced =
      run_tetra("sim " + dir.file("s.yaml") + " --fault gyro=3,kind=stuck,at=20 -o " + dir.file("b.csv"));
  ASSERT_EQ(replaced.exit_status, 0) << replaced.err;
  EXPECT_EQ(fault_lines(dir.file("b.csv")), std::vector<std::string>{"gyro=3,kind=stuck,at=20"});

  const auto added =
      run_tetra("sim " + dir.file("s.yaml") + " --add-fault gyro=3,kind=stuck,at=20 -o " + dir.file("c.csv"));
  ASSERT_EQ(added.exit_status, 0) << added.err;
  EXPECT_EQ(fault_lines(dir.file("c.csv")),
            (std::vector<std::string>{"gyro=2,kind=bias,at=10,size=0.01", "gyro=3,kind=stuck,at=20"}));
}

TEST(SimCli, WriteUnitWritesTheShippedSeedUnit) {
  TempDir dir;
  const auto written = run_tetra("sim --write-unit " + dir.file("unit.yaml"));
  ASSERT_EQ(written.exit_status, 0) << written.err;
  EXPECT_EQ(without_comments(dir.file("unit.yaml")), without_comments(source_path("examples/seed_unit.yaml")))
      << "examples/seed_unit.yaml is no longer what `tetra sim --write-unit` writes";
  // The file as --unit simulates what the default unit does (same seed: the same samples).
  ASSERT_EQ(run_tetra("sim static --minutes 1 -o " + dir.file("a.csv")).exit_status, 0);
  ASSERT_EQ(run_tetra("sim static --minutes 1 --unit " + dir.file("unit.yaml") + " -o " + dir.file("b.csv"))
                .exit_status,
            0);
  EXPECT_EQ(without_comments(dir.file("a.csv")), without_comments(dir.file("b.csv")));
  const auto both = run_tetra("sim orbit --write-unit " + dir.file("u2.yaml"));
  EXPECT_EQ(both.exit_status, 2) << both.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("u2.yaml")));
}

// README.md's `--compare` example, as its prose writes it, runs and prints the ratios it quotes (without `-o`
// it exited 2: `--output is required`).
TEST(Readme, CompareExampleRunsAsWritten) {
  const std::string readme = read_file(source_path("README.md"));
  const std::string start = "`tetra calibrate examples/turntable.csv";
  const auto at = readme.find(start);
  ASSERT_NE(at, std::string::npos);
  std::string command = readme.substr(at + 7, readme.find('`', at + 1) - at - 7);  // after "`tetra "
  TempDir dir;
  for (const std::string file : {"examples/turntable.csv", "examples/factory.yaml"})
    command.replace(command.find(file), file.size(), source_path(file));
  command.replace(command.find("cal.yaml"), 8, dir.file("cal.yaml"));
  const auto r = run_tetra(command);
  ASSERT_EQ(r.exit_status, 0) << command << "\n" << r.err;
  EXPECT_NE(r.out.find("4.25e+04  g2 2.24e+05  g3 5.11e+04  g4 1.44e+05"), std::string::npos) << r.out;
}

// `sim --dds` writes no files: --out and --truth are refused (exit 2, one line naming both) before any DDS
// entity is made, never silently ignored (before the change: a run without readers, exit 1, and no file).
TEST(SimCli, DdsRefusesOutAndTruthInsteadOfIgnoringThem) {
  TempDir dir;
  for (const std::string option : {"--truth", "-o"}) {
    const auto r = run_tetra("sim orbit --dds --domain 226 --minutes 0.1 --wait-timeout 1 " + option + " " +
                             dir.file("f.csv"));
    EXPECT_EQ(r.exit_status, 2) << option << ": " << r.err;
    EXPECT_NE(r.err.find("--out and --truth do not apply with --dds"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("f.csv")));
  }
}

TEST(FusionCli, ShippedServiceConfigurationIsAcceptedAndItsReadersTimeoutNamesTheRefusedQos) {
  ASSERT_TRUE(kLoopback);
  TempDir dir;
  TetraProcess fusion({"fusion", "--config", source_path("examples/fusion_service.yaml"), "--domain", "226"},
                      dir.file("fusion.log"));
  ASSERT_TRUE(eventually([&] {
    return read_file(dir.file("fusion.log")).find("running") != std::string::npos;
  })) << read_file(dir.file("fusion.log"));
  // The service expects 100 Hz (deadline 3 periods = 0.03 s); a sensor at 10 Hz offers 0.3 s: refused.
  const auto sim = run_tetra(
      "sim orbit --dds --dds-unit tetra-1 --domain 226 --minutes 0.1 --reference-hz 0 --wait-timeout 5");
  EXPECT_EQ(sim.exit_status, 1) << sim.err;
  EXPECT_NE(sim.err.find("0 of 1 GyroSample readers appeared"), std::string::npos) << sim.err;
  EXPECT_NE(sim.err.find("refused this writer's QoS: deadline"), std::string::npos) << sim.err;
  EXPECT_EQ(fusion.signal_and_wait(SIGTERM), 0) << read_file(dir.file("fusion.log"));
}

TEST(CampaignCli, DomainOptionAppliesToDdsCampaignsOnly) {
  TempDir dir;
  write_file(dir.file("c.yaml"),
             "loop: open\nscenarios: [orbit]\nduration_s: 60\nkinds: [stuck]\ngyros: [3]\n"
             "onsets_s: [30]\nseeds: [1]\n");
  const auto result =
      run_tetra("campaign " + dir.file("c.yaml") + " --out " + dir.file("out") + " --domain 5");
  EXPECT_EQ(result.exit_status, 2) << result.err;
  EXPECT_NE(result.err.find("--domain"), std::string::npos) << result.err;
}

// SIGTERM while the services run: the campaign stops its workers, each worker's service follows it, the
// finished rows stay, and the same command finishes the rest.
TEST(CampaignCli, SigtermStopsWorkersAndServicesAndTheSameCommandResumes) {
  ASSERT_TRUE(kLoopback);
  TempDir dir;
  write_file(dir.file("c.yaml"),
             "loop: open\nscenarios: [orbit]\nduration_s: 40\nkinds: [stuck]\ngyros: [1, 2, 3]\n"
             "onsets_s: [20]\nseeds: [1]\ntarget: dds\ndomain: 3\n");
  const std::string out = dir.file("out");
  {
    TetraProcess campaign(
        {"campaign", dir.file("c.yaml"), "--out", out, "--jobs", "2", "--no-report", "--domain", "227"},
        dir.file("campaign.log"));
    ASSERT_TRUE(eventually([&] { return processes_mentioning(out + "/dds/") >= 1; }))
        << read_file(dir.file("campaign.log"));
    EXPECT_EQ(campaign.signal_and_wait(SIGTERM), 1) << read_file(dir.file("campaign.log"));
    const std::string log = read_file(dir.file("campaign.log"));
    EXPECT_NE(log.find("domain 227"), std::string::npos) << log;
    EXPECT_NE(log.find("interrupted by SIGTERM"), std::string::npos) << log;
  }
  // The services get SIGTERM when their worker ends; allow them their orderly exit.
  EXPECT_TRUE(eventually([&] { return processes_mentioning(out) == 0; }, std::chrono::seconds(20)))
      << processes_mentioning(out) << " processes of the campaign are still running";
  const auto resumed =
      run_tetra("campaign " + dir.file("c.yaml") + " --out " + out + " --jobs 2 --no-report --domain 227");
  ASSERT_EQ(resumed.exit_status, 0) << resumed.err;
  std::istringstream rows(read_file(out + "/runs.csv"));
  int n = 0;
  for (std::string line; std::getline(rows, line);) ++n;
  EXPECT_EQ(n, 1 + 3) << "header and the 3 runs, each once";
}

}  // namespace
}  // namespace tetra::test
