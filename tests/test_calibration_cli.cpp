// `tetra calibrate` on bad input: exit status 2 and exactly one line on stderr
// naming the file, the line and the problem. One test per case.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/frames.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/units.hpp"

namespace tetra {
namespace {

struct PlanStep {
  bool inner_turns;  //!< true: inner gimbal rotates, outer fixed
  double fixed_deg;  //!< [deg] angle of the fixed gimbal
  double rate_dps;   //!< [deg/s] rate of the turning gimbal (0: does not turn)
};

//! The geometry of seed Table 3 as gimbal motions (the body rates are derived by the program).
std::vector<PlanStep> seed_plan() {
  std::vector<PlanStep> plan;
  const std::pair<bool, double> positions[8] = {{true, 0.0},   {true, 180.0},  {false, 0.0},  {false, 180.0},
                                                {false, 90.0}, {false, -90.0}, {false, 30.0}, {false, -30.0}};
  for (const auto& [inner, fixed] : positions) {
    plan.push_back({inner, fixed, 6.0});
    plan.push_back({inner, fixed, -6.0});
  }
  return plan;
}

//! A small well-formed turntable file: `rows` rows per step at 1 Hz, plausible voltages. Line 1 is the
//! latitude comment, line 2 the header, so row k of the file is on line k + 3.
std::string turntable_text(const std::vector<PlanStep>& plan, int rows = 6,
                           const std::string& header = "sequence,time_s,inner_deg,outer_deg,g1,g2,g3,g4") {
  const Eigen::Matrix<double, 4, 3> axes = nominal_tetrahedron_axes();
  std::string out = "# latitude_deg=-23.2\n" + header + "\n";
  double t = 0.0;
  for (std::size_t k = 0; k < plan.size(); ++k) {
    for (int r = 0; r < rows; ++r, t += 1.0) {
      const double turning = plan[k].rate_dps * r;
      const double inner = plan[k].inner_turns ? turning : plan[k].fixed_deg;
      const double outer = plan[k].inner_turns ? plan[k].fixed_deg : turning;
      out += std::to_string(k + 1) + ",";
      append_double(out, t);
      out += ",";
      append_double(out, inner);
      out += ",";
      append_double(out, outer);
      // Noise-free outputs of a nominal unit (Earth rate ignored: these files test parsing, not accuracy).
      const Eigen::Vector3d rate_B_dps =
          turntable_rate_B(inner * kDegToRad, plan[k].inner_turns ? plan[k].rate_dps : 0.0,
                           plan[k].inner_turns ? 0.0 : plan[k].rate_dps);
      for (int i = 0; i < 4; ++i) {
        out += ",";
        append_double(out, 0.075 * axes.row(i).dot(rate_B_dps) + 0.2);
      }
      out += "\n";
    }
  }
  return out;
}

//! Runs calibrate on `text` and checks exit 2 and one stderr line containing "FILE:LINE:" and `problem`.
void expect_bad_input(const std::string& text, const std::string& line, const std::string& problem,
                      const std::string& extra_args = "") {
  test::TempDir dir;
  const std::string path = dir.file("table.csv");
  test::write_file(path, text);
  const auto r = test::run_tetra("calibrate " + path + " -o " + dir.file("cal.yaml") + " " + extra_args);
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(path + ":" + line + ":"), std::string::npos)
      << "expected line " << line << ": " << r.err;
  EXPECT_NE(r.err.find(problem), std::string::npos) << "expected '" << problem << "': " << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir.file("cal.yaml")));
}

// The generator itself must produce a file the program accepts, or the cases below prove nothing.
TEST(CalibrateCli, WellFormedSmallFileIsAccepted) {
  test::TempDir dir;
  const std::string path = dir.file("table.csv");
  test::write_file(path, turntable_text(seed_plan()));
  const auto r = test::run_tetra("calibrate " + path + " -o " + dir.file("cal.yaml"));
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("cal.yaml")));
}

TEST(CalibrateCli, MissingColumn) {
  expect_bad_input(turntable_text(seed_plan(), 6, "sequence,time_s,inner_deg,outer_angle,g1,g2,g3,g4"), "2",
                   "header: missing column 'outer_deg'");
}

TEST(CalibrateCli, NonNumericCell) {
  std::string text = turntable_text(seed_plan());
  // Line 7 is the fifth data row; replace its g2 value.
  const std::size_t line7 = [&] {
    std::size_t pos = 0;
    for (int l = 1; l < 7; ++l) pos = text.find('\n', pos) + 1;
    return pos;
  }();
  // Fifth data row: sequence 1, time 4; its g2 is the sixth field.
  std::size_t g2 = line7;
  for (int comma = 0; comma < 5; ++comma) g2 = text.find(',', g2) + 1;
  text.replace(g2, text.find(',', g2) - g2, "abc");
  expect_bad_input(text, "7", "column 'g2': 'abc' is not a number");
}

TEST(CalibrateCli, SequenceWithoutItsPair) {
  auto plan = seed_plan();
  plan.pop_back();  // sequence 15 loses sequence 16; its first row is data row 14·6 → line 87
  expect_bad_input(turntable_text(plan), "87",
                   "sequence 15 (lines 87-92): has no pair: sequence 16 is missing");
}

TEST(CalibrateCli, FewerThanThreeGyros) {
  std::string text = turntable_text(seed_plan(), 6, "sequence,time_s,inner_deg,outer_deg,g1,g2,x3,x4");
  expect_bad_input(text, "2", "2 gyro columns (g1, g2, ...) found, calibration needs at least 3");
}

TEST(CalibrateCli, TimeGoingBackwards) {
  std::string text = turntable_text(seed_plan());
  // Data row 10 (line 12) has time 9; make it 2.5 (earlier than row 9's 8).
  const std::string row10 = "\n2,9,";
  const std::size_t at = text.find(row10);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, row10.size(), "\n2,2.5,");
  expect_bad_input(text, "12", "column 'time_s': time goes backwards");
}

TEST(CalibrateCli, RotatingSequenceWhoseAngleDoesNotChange) {
  auto plan = seed_plan();
  plan[5].rate_dps = 0.0;  // sequence 6 should turn the outer gimbal but stands still; lines 33-38
  expect_bad_input(turntable_text(plan), "33", "sequence 6 (lines 33-38): neither gimbal rotates");
}

TEST(CalibrateCli, EmptyFile) {
  expect_bad_input("", "1", "empty file");
}

// Further checks of meaning, beyond the list.
TEST(CalibrateCli, PairTurningTheSameWay) {
  auto plan = seed_plan();
  plan[3].rate_dps = 6.0;  // sequence 4 (lines 21-26) repeats sequence 3's direction
  expect_bad_input(turntable_text(plan), "21",
                   "sequence 4 (lines 21-26): pairs with sequence 3 but turns in the same direction");
}

TEST(CalibrateCli, PairAtDifferentFixedAngles) {
  auto plan = seed_plan();
  plan[9].fixed_deg = 80.0;  // sequence 10 (lines 57-62) at inner 80° where sequence 9 is at 90°
  expect_bad_input(turntable_text(plan), "57",
                   "holds the other gimbal at 80.0000 deg instead of 90.0000 deg");
}

TEST(CalibrateCli, BothGimbalsMove) {
  std::string text = turntable_text(seed_plan());
  // Sequence 5 turns the outer gimbal with the inner at 0°; nudge the inner angle on its third row
  // (data row 26, line 29: time 26, inner 0 → 2); the message names the sequence's first line.
  const std::string row = "\n5,26,0,";
  const std::size_t at = text.find(row);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, row.size(), "\n5,26,2,");
  expect_bad_input(text, "27", "sequence 5 (lines 27-32): both gimbals move");
}

TEST(CalibrateCli, SequenceNotContiguous) {
  auto plan = seed_plan();
  std::string text = turntable_text(plan);
  // Relabel sequence 3's last row (data row 17, line 20) as sequence 1.
  const std::string row = "\n3,17,";
  const std::size_t at = text.find(row);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, row.size(), "\n1,17,");
  expect_bad_input(text, "20", "sequence 1 appears again");
}

TEST(CalibrateCli, PlanExcitingOnlyTwoAxes) {
  auto plan = seed_plan();
  plan.resize(8);  // sequences 1-8: rotations about body X and Y only
  test::TempDir dir;
  test::write_file(dir.file("t.csv"), turntable_text(plan));
  const auto r = test::run_tetra("calibrate " + dir.file("t.csv") + " -o " + dir.file("c.yaml"));
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("excite only 2 independent body axes"), std::string::npos) << r.err;
}

// Not in the list but part of the contract: no latitude anywhere is bad input.
TEST(CalibrateCli, NoLatitude) {
  std::string text = turntable_text(seed_plan());
  text.erase(0, text.find('\n') + 1);
  test::TempDir dir;
  test::write_file(dir.file("t.csv"), text);
  const auto r = test::run_tetra("calibrate " + dir.file("t.csv") + " -o " + dir.file("c.yaml"));
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("no latitude"), std::string::npos) << r.err;
  // ... and --latitude supplies it.
  EXPECT_EQ(test::run_tetra("calibrate " + dir.file("t.csv") + " --latitude -23.2 -o " + dir.file("c.yaml"))
                .exit_status,
            0);
}

TEST(CalibrateCli, BiasModelOnlyWithSixteen) {
  test::TempDir dir;
  test::write_file(dir.file("t.csv"), turntable_text(seed_plan()));
  const auto r = test::run_tetra("calibrate " + dir.file("t.csv") + " --method batch --bias-model seed -o " +
                                 dir.file("c.yaml"));
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--bias-model applies to --method sixteen only"), std::string::npos) << r.err;
}

// The example data (seed unit with its Table 6 noise, 2 Hz): the command writes a calibration file that
// reads back and is close to the unit that was simulated. Tolerances: the figures (s 1e-5
// relative, axes 1e-5, β 2e-6 V); the example's noise (σ(β) ≈ 8e-8 V) is far below them.
TEST(CalibrateCli, ExampleWithCompare) {
  test::TempDir dir;
  const auto r = test::run_tetra("calibrate " + test::source_path("examples/turntable.csv") + " --compare " +
                                 test::source_path("examples/factory.yaml") + " -o " + dir.file("cal.yaml"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("cf. seed Table 4"), std::string::npos);
  EXPECT_NE(r.out.find("cf. seed Table 5"), std::string::npos);
  EXPECT_NE(r.out.find("cf. seed Fig. 4"), std::string::npos);
  auto cal = read_calibration(dir.file("cal.yaml"));
  ASSERT_TRUE(cal.ok()) << cal.error().message;
  EXPECT_EQ(cal->method, "sixteen-position");
  EXPECT_EQ(cal->unit, "seed-as-built");  // from the file's '# unit=' comment
  ASSERT_TRUE(cal->latitude_deg.has_value());
  EXPECT_DOUBLE_EQ(*cal->latitude_deg, -23.2);
  const Calibration truth = seed_as_built_unit();
  ASSERT_EQ(cal->gyro_count(), 4);
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& e = cal->gyros[i];
    const auto& t = truth.gyros[i];
    EXPECT_NEAR(e.scale_factor_V_per_dps / t.scale_factor_V_per_dps, 1.0, 1e-5) << "gyro " << i + 1;
    EXPECT_NEAR(e.bias_V, t.bias_V, 2e-6) << "gyro " << i + 1;
    EXPECT_LT((e.axis_B - t.axis_B).cwiseAbs().maxCoeff(), 1e-5) << "gyro " << i + 1;
    ASSERT_TRUE(e.sigma.has_value());
    EXPECT_GT(e.sigma->bias_V, 0.0);
  }
}

TEST(CalibrateCli, SeedBiasModelIsLabelledAndQuantified) {
  test::TempDir dir;
  const auto r = test::run_tetra("calibrate " + test::source_path("examples/turntable.csv") +
                                 " --bias-model seed -o " + dir.file("cal.yaml"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("Seed eq. 11 bias minus body-model bias"), std::string::npos);
  auto cal = read_calibration(dir.file("cal.yaml"));
  ASSERT_TRUE(cal.ok()) << cal.error().message;
  EXPECT_EQ(cal->method, "sixteen-position-seed-bias");
}

TEST(CalibrateCli, CompareWithOtherGyroCount) {
  test::TempDir dir;
  Calibration three = seed_as_built_unit();
  three.gyros.resize(3);
  ASSERT_TRUE(write_calibration(dir.file("three.yaml"), three).ok());
  const auto r = test::run_tetra("calibrate " + test::source_path("examples/turntable.csv") + " --compare " +
                                 dir.file("three.yaml") + " -o " + dir.file("cal.yaml"));
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("three.yaml: has 3 gyros"), std::string::npos) << r.err;
}

TEST(CalibrateCli, HelpNamesEveryOption) {
  const auto r = test::run_tetra("calibrate --help");
  EXPECT_EQ(r.exit_status, 0);
  for (const char* option : {"--latitude", "--method", "--bias-model", "--compare", "--output"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
}

// --noise: the unit's bias instability widens the bias 1σ (the sequence means share it: docs/calibration.md),
// the estimates themselves unchanged; a noise file without `noise:` sections is bad input naming it.
TEST(CalibrateCli, NoiseModelWidensTheBiasSigmaOnly) {
  test::TempDir dir;
  std::string noisy = test::read_file(test::source_path("examples/factory.yaml"));
  std::string with_noise;
  std::istringstream lines(noisy);
  for (std::string line; std::getline(lines, line);) {
    with_noise += line + "\n";
    if (line.find("axis:") != std::string::npos)
      with_noise += "    noise: {arw_dps_rtHz: 3.0e-5, bias_instability_dps: 5.0e-6}\n";
  }
  test::write_file(dir.file("noise.yaml"), with_noise);
  const std::string table = test::source_path("examples/turntable.csv");
  const auto white = test::run_tetra("calibrate " + table + " -o " + dir.file("white.yaml"));
  ASSERT_EQ(white.exit_status, 0) << white.err;
  const auto model = test::run_tetra("calibrate " + table + " --noise " + dir.file("noise.yaml") + " -o " +
                                     dir.file("model.yaml"));
  ASSERT_EQ(model.exit_status, 0) << model.err;
  EXPECT_NE(model.out.find("(--noise)"), std::string::npos) << model.out;
  auto a = read_calibration(dir.file("white.yaml"));
  auto b = read_calibration(dir.file("model.yaml"));
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(a->gyros[i].bias_V, b->gyros[i].bias_V);  // the estimate is the same, bit for bit
    EXPECT_GT(b->gyros[i].sigma->bias_V, a->gyros[i].sigma->bias_V);
  }
  const auto bad =
      test::run_tetra("calibrate " + table + " --noise " + test::source_path("examples/factory.yaml") +
                      " -o " + dir.file("bad.yaml"));
  EXPECT_EQ(bad.exit_status, 2) << bad.err;
  EXPECT_NE(bad.err.find("factory.yaml: gyro 1 has no 'noise:' section"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.yaml")));
}

}  // namespace
}  // namespace tetra
