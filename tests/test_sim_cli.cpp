// tetra sim on the command line: outputs readable by the core readers, byte-identical reruns,
// exit 2 with one clear line for bad scenario files and fault specs.
#include <gtest/gtest.h>

#include <algorithm>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/turntable_log.hpp"

namespace tetra {
namespace {

using test::read_file;
using test::run_tetra;
using test::TempDir;
using test::write_file;

std::size_t lines(const std::string& s) {
  return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

TEST(SimCli, HelpExitsZero) {
  auto r = run_tetra("sim --help");
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_NE(r.out.find("--fault"), std::string::npos);
}

// The file without its provenance lines (command line and time differ from run to run).
std::string without_provenance(const std::string& text) {
  std::string out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string line = text.substr(pos, end - pos);
    bool provenance = false;
    for (const char* key : {"# tetra_version=", "# command=", "# inputs=", "# created_utc="})
      provenance = provenance || line.rfind(key, 0) == 0;
    if (!provenance) out += line + '\n';
    pos = end + 1;
  }
  return out;
}

TEST(SimCli, SameSeedGivesByteIdenticalFilesAndTheReadersAcceptThem) {
  TempDir dir;
  const std::string args =
      " --minutes 2 --rate-hz 50 --fault gyro=2,kind=bias,at=30,size=0.1,until=60 --seed 77";
  auto a = run_tetra("sim slews" + args + " --out " + dir.file("a.csv") + " --truth " + dir.file("ta.csv"));
  auto b = run_tetra("sim slews" + args + " --out " + dir.file("b.csv") + " --truth " + dir.file("tb.csv"));
  ASSERT_EQ(a.exit_status, 0) << a.err;
  ASSERT_EQ(b.exit_status, 0) << b.err;
  EXPECT_EQ(without_provenance(read_file(dir.file("a.csv"))),
            without_provenance(read_file(dir.file("b.csv"))));
  EXPECT_EQ(without_provenance(read_file(dir.file("ta.csv"))),
            without_provenance(read_file(dir.file("tb.csv"))));
  auto c = run_tetra("sim slews --minutes 2 --rate-hz 50 --seed 78 --out " + dir.file("c.csv"));
  ASSERT_EQ(c.exit_status, 0) << c.err;
  EXPECT_NE(read_file(dir.file("a.csv")), read_file(dir.file("c.csv")));

  auto log = read_gyro_log(dir.file("a.csv"));
  ASSERT_TRUE(log.ok()) << log.error().message;
  EXPECT_EQ(log->epochs(), 6000u);  // 2 min at 50 Hz
  EXPECT_EQ(log->gyro_count, 4);
  EXPECT_TRUE(log->has_reference);
  EXPECT_EQ(log->meta("fault"), "gyro=2;kind=bias;at=30;size=0.1;until=60");
  EXPECT_EQ(log->meta("reference_frame"), "inertial");
  // Truth: header + one row per epoch after the metadata comments.
  const std::string truth = read_file(dir.file("ta.csv"));
  EXPECT_NE(truth.find("\ntime_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps\n"), std::string::npos);
  EXPECT_EQ(lines(truth.substr(truth.find("time_s,qw"))), 6001u);
}

TEST(SimCli, TurntableWritesTheCalibrationInput) {
  TempDir dir;
  auto r =
      run_tetra("sim turntable --rate-hz 2 --latitude 10 --order 1,2,3,4 --wrap --out " + dir.file("t.csv"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  auto log = read_turntable_log(dir.file("t.csv"));
  ASSERT_TRUE(log.ok()) << log.error().message;
  EXPECT_EQ(log->rows(), 4u * 120u);
  EXPECT_EQ(log->meta("latitude_deg"), "10");
  EXPECT_EQ(log->meta("encoder_angles"), "wrapped");
}

TEST(SimCli, BadInputExitsTwoWithOneClearLine) {
  TempDir dir;
  write_file(dir.file("bad.yaml"), "scenario: orbit\nrate_hz: 10\nreference: {hz: 1}\n");
  write_file(dir.file("badfault.yaml"), "scenario: orbit\nfaults: [\"gyro=1,kind=bias,at=1\"]\n");
  write_file(dir.file("period.yaml"), "scenario: orbit\norbit_period_s: 1e-300\n");
  write_file(dir.file("inertia.yaml"),
             "scenario: orbit\nclosed_loop:\n  inertia_kg_m2: [1e300, 1e300, 1e300]\n");
  write_file(dir.file("torque.yaml"),
             "scenario: orbit\nclosed_loop:\n  disturbance: {constant_Nm: [1e300, 0, 0]}\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"sim orbit --fault gyro=1,kind=melt,at=3 --out " + dir.file("x.csv"), "unknown kind 'melt'"},
      {"sim orbit --fault gyro=7,kind=zero,at=3 --out " + dir.file("x.csv"), "gyro 7 does not exist"},
      {"sim orbit --fault gyro=1,kind=bias,at=3 --out " + dir.file("x.csv"), "size is required"},
      {"sim " + dir.file("bad.yaml") + " --out " + dir.file("x.csv"),
       "bad.yaml:3: reference: unknown key 'hz'"},
      {"sim " + dir.file("badfault.yaml") + " --out " + dir.file("x.csv"), "badfault.yaml:2: faults[0]"},
      {"sim " + dir.file("missing.yaml") + " --out " + dir.file("x.csv"), "missing.yaml: cannot open"},
      {"sim wobble --out " + dir.file("x.csv"), "unknown scenario 'wobble'"},
      {"sim static --rate-hz 0 --out " + dir.file("x.csv"), "--rate-hz"},
      {"sim static --minutes -1 --out " + dir.file("x.csv"), "--minutes"},
      {"sim static --drop 2 --out " + dir.file("x.csv"), "--drop"},
      {"sim static --jitter 0.2 --out " + dir.file("x.csv"), "jitter_s"},
      {"sim static", "--out"},
      {"sim turntable --order 1,99", "sequence 99"},
      {"sim turntable --minutes 3", "--minutes does not apply"},
      {"sim orbit --wrap --out " + dir.file("x.csv"), "--wrap applies to the turntable scenario only"},
      {"sim orbit --unit " + dir.file("nounit.yaml") + " --out " + dir.file("x.csv"), "nounit.yaml"},
      // Physical ranges (docs/sim.md, "Ranges"): these wrote all-NaN logs with exit 0.
      {"sim orbit --acs-amplitude 1e300 --out " + dir.file("x.csv"),
       "--acs-amplitude: '1e300' must be from 0 to 45"},
      {"sim orbit --orbit-period 1e-300 --out " + dir.file("x.csv"),
       "--orbit-period: '1e-300' must be from 20 to"},
      {"sim orbit --minutes 1e7 --rate-hz 100 --out " + dir.file("x.csv"), "(with --rate-hz, --minutes)"},
      {"sim " + dir.file("period.yaml") + " --out " + dir.file("x.csv"),
       "period.yaml:2: orbit_period_s must be"},
      {"sim " + dir.file("inertia.yaml") + " --closed-loop", "inertia.yaml:3: closed_loop: inertia_kg_m2"},
      {"sim " + dir.file("torque.yaml") + " --closed-loop",
       "torque.yaml:3: closed_loop: disturbance.constant_Nm[0]"},
  };
  for (const auto& [args, needle] : cases) {
    auto r = run_tetra(args);
    EXPECT_EQ(r.exit_status, 2) << args << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1u) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.csv")));
  // An infinite duration: one short line (CLI11's own check printed a 300-digit bound).
  const auto inf = run_tetra("sim orbit --minutes inf --out " + dir.file("x.csv"));
  EXPECT_EQ(inf.exit_status, 2) << inf.err;
  EXPECT_NE(inf.err.find("--minutes: 'inf' must be above 0 and at most 1e+07"), std::string::npos) << inf.err;
  EXPECT_LT(inf.err.size(), 120u) << inf.err;
}

}  // namespace
}  // namespace tetra

namespace tetra {
namespace {

// Acceptance: the turntable output, calibrated by `tetra calibrate`, returns the truth unit within
// the accuracy the calibration issue states for this case (seed unit, 1 turn per sequence at
// 10 Hz, white rate noise 3e-5 deg/√s): s to 1e-5 relative, axes to 1e-5, β to 2e-6 V.
TEST(SimCli, AScenarioFileIsJudgedAgainstTheUnitOfTheRun) {
  // A warm-up and a fault written for a five-gyro unit, run with --unit of five gyros: the file was judged
  // against the default four-gyro unit before --unit replaced it ("thermal.bias_dps_per_K has 5
  // coefficients; the unit has 4 gyros"), so a scenario for any N ≠ 4 could not run from the command line.
  TempDir dir;
  write_file(dir.file("warm5.yaml"),
             "scenario: orbit\nduration_s: 60\nrate_hz: 10\nfaults: [\"gyro=5,kind=bias,at=30,size=0.01\"]\n"
             "thermal: {start_C: 0, end_C: 20, time_constant_s: 300,\n"
             "          bias_dps_per_K: [1e-6, 1.2e-6, 0.8e-6, 1.5e-6, 1.1e-6]}\n");
  const std::string unit5 = std::string(TETRA_SOURCE_DIR) + "/examples/sim/calibrated_unit_5.yaml";
  const auto r =
      run_tetra("sim " + dir.file("warm5.yaml") + " --unit " + unit5 + " --out " + dir.file("a.csv"));
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("a.csv")));
  // Without --unit the file still names its line against the unit it gets.
  const auto four = run_tetra("sim " + dir.file("warm5.yaml") + " --out " + dir.file("b.csv"));
  EXPECT_EQ(four.exit_status, 2);
  EXPECT_NE(four.err.find("warm5.yaml:"), std::string::npos) << four.err;
  EXPECT_NE(four.err.find("the unit has 4 gyros"), std::string::npos) << four.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("b.csv")));
}

TEST(SimCli, TurntableCalibratedByTetraCalibrateReturnsTheTruthUnit) {
  const auto help = run_tetra("calibrate --help");
  if (help.exit_status != 0) GTEST_SKIP() << "tetra calibrate is not part of this build yet";
  TempDir dir;
  Calibration truth = seed_as_built_unit();
  for (auto& g : truth.gyros) {
    GyroNoise white;
    white.arw_dps_rtHz = 3.0e-5;
    g.noise = white;
  }
  ASSERT_TRUE(write_calibration(dir.file("truth.yaml"), truth).ok());
  auto sim =
      run_tetra("sim turntable --seed 11 --unit " + dir.file("truth.yaml") + " --out " + dir.file("t.csv"));
  ASSERT_EQ(sim.exit_status, 0) << sim.err;
  auto cal = run_tetra("calibrate " + dir.file("t.csv") + " -o " + dir.file("cal.yaml"));
  ASSERT_EQ(cal.exit_status, 0) << cal.err;
  auto estimated = read_calibration(dir.file("cal.yaml"));
  ASSERT_TRUE(estimated.ok()) << estimated.error().message;
  ASSERT_EQ(estimated->gyro_count(), 4);
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& e = estimated->gyros[i];
    const auto& t = truth.gyros[i];
    EXPECT_NEAR(e.scale_factor_V_per_dps / t.scale_factor_V_per_dps, 1.0, 1e-5) << "gyro " << i + 1;
    EXPECT_LT((e.axis_B - t.axis_B).norm(), 1e-5) << "gyro " << i + 1;
    EXPECT_NEAR(e.bias_V, t.bias_V, 2e-6) << "gyro " << i + 1;
  }
}

}  // namespace
}  // namespace tetra
