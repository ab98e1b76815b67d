// `tetra score` (docs/score.md): the metrics on synthetic series with known answers, reading and its
// errors, and the command end to end (bad input, plot and JSON written, inputs never overwritten, the
// seed experiment's 360° turn printed by the command).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "test_support.hpp"
#include "tetra/core/attitude_score.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/core/units.hpp"

namespace tetra {
namespace {

using test::run_tetra;

//! A row of an attitude (with sigma) or truth file.
std::string row(double t, const Quaternion& q, const Eigen::Vector3d& w_dps, const std::string& sigma = "") {
  std::string out;
  append_double(out, t);
  for (const double c : to_wxyz(q)) {
    out += ',';
    append_double(out, c);
  }
  for (int k = 0; k < 3; ++k) {
    out += ',';
    append_double(out, w_dps(k));
  }
  return out + sigma + "\n";
}

constexpr const char* kTruthHeader = "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps\n";
constexpr const char* kAttHeader = "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros\n";
constexpr const char* kAttAxisHeader =
    "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros,sigma_x_deg,sigma_y_deg,sigma_z_deg,bias_1_"
    "dps\n";

//! Truth turning about z at 1 deg/s from identity, `hz` rows per second over [0, 100] s.
std::string turning_truth(double hz) {
  std::string text = kTruthHeader;
  for (int k = 0; k <= static_cast<int>(100 * hz); ++k) {
    const double t = k / hz;
    text += row(t, quat_exp(Eigen::Vector3d(0, 0, t * kDegToRad)), Eigen::Vector3d(0, 0, 1.0));
  }
  return text;
}

AttitudeSeries parse(const std::string& text, bool with_sigma) {
  auto s = parse_attitude_series(text, "mem.csv", with_sigma);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  return s.ok() ? *s : AttitudeSeries{};
}

// A constant body-frame error e = (0.5, −1.5, 2.5)·σ with per-axis σ = 1e-3°: NEES = 0.25 + 2.25 + 6.25 =
// 8.75 at every epoch; x within 1σ, y within 2σ, z within 3σ; |e| = 2.958σ, σ_total = √3·σ, so the total
// angle is within 2σ_total but not 1σ_total. Rounding of the written numbers: 1e-9 relative at most.
TEST(ScoreMetrics, ConstantErrorWithPerAxisSigma) {
  const double sigma = 1e-3;
  const Eigen::Vector3d e_deg = Eigen::Vector3d(0.5, -1.5, 2.5) * sigma;
  std::string att = kAttAxisHeader;
  for (int k = 0; k <= 100; ++k) {
    const Quaternion truth = quat_exp(Eigen::Vector3d(0, 0, k * kDegToRad));
    const Quaternion est = truth * quat_exp(e_deg * kDegToRad);
    att +=
        row(k, est, Eigen::Vector3d(0, 0, 1.0), ",0.0017320508075688772,NOMINAL,1;2;10,0.001,0.001,0.001,0");
  }
  auto score = score_attitude(parse(att, true), parse(turning_truth(1.0), false));
  ASSERT_TRUE(score.ok()) << score.error().message;
  EXPECT_TRUE(score->per_axis_sigma);
  EXPECT_EQ(score->epochs.size(), 101U);
  EXPECT_EQ(score->exact_matches, 101U);
  EXPECT_EQ(score->nees_dof, 3);
  EXPECT_NEAR(score->mean_nees, 8.75, 1e-6);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(score->rms_B_deg(k), std::abs(e_deg(k)), 1e-12);
    EXPECT_NEAR(score->epochs.back().error_B_deg(k), e_deg(k), 1e-12);
  }
  EXPECT_NEAR(score->rms_total_deg, e_deg.norm(), 1e-12);
  EXPECT_EQ(score->within_B[0], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(score->within_B[1], Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(score->within_B[2], Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(score->within_total[0], 0.0);
  EXPECT_EQ(score->within_total[1], 1.0);
  EXPECT_EQ(score->within_total[2], 1.0);
  // Integrated angle: 1 deg/s about z for 100 s; the --axis default y sees nothing.
  EXPECT_NEAR(score->angle_B_deg(2), 100.0, 1e-9);
  EXPECT_NEAR(score->truth_angle_B_deg(2), 100.0, 1e-9);
  EXPECT_NEAR(score->angle_axis_deg, 0.0, 1e-12);
}

// Without per-axis columns: |e|²/σ² with the total sigma. Half the epochs have sigma 0 (nothing stated):
// left out and counted. e = 2e-3° about x, σ = 1e-3° → 4 at every stated epoch.
TEST(ScoreMetrics, TotalSigmaAndEpochsWithoutSigma) {
  std::string att = kAttHeader;
  for (int k = 0; k <= 100; ++k) {
    const Quaternion truth = quat_exp(Eigen::Vector3d(0, 0, k * kDegToRad));
    const Quaternion est = truth * quat_exp(Eigen::Vector3d(2e-3 * kDegToRad, 0, 0));
    att += row(k, est, Eigen::Vector3d(0, 0, 1.0), k % 2 == 0 ? ",0,SUSPECT,1234" : ",0.001,NOMINAL,1234");
  }
  auto score = score_attitude(parse(att, true), parse(turning_truth(1.0), false));
  ASSERT_TRUE(score.ok());
  EXPECT_FALSE(score->per_axis_sigma);
  EXPECT_EQ(score->nees_dof, 1);
  EXPECT_EQ(score->sigma_epochs, 50U);
  EXPECT_EQ(score->no_sigma_epochs, 51U);
  EXPECT_NEAR(score->mean_nees, 4.0, 1e-6);
  EXPECT_EQ(score->within_total[0], 0.0);
  EXPECT_EQ(score->within_total[1], 1.0);
  EXPECT_TRUE(std::isnan(score->within_B[0](0)));
}

// Different rates: truth at 10 Hz, the estimate (equal to the truth) at 1 Hz shifted by 0.05 s, so
// every row falls between two truth rows. Slerp is exact for a constant-rate turn about a fixed axis:
// the error is rounding only (1e-9°). Rows beyond the truth's 100 s are counted, not scored.
TEST(ScoreMetrics, DifferentRatesInterpolateTheTruth) {
  std::string att = kAttHeader;
  for (int k = 0; k <= 110; ++k) {
    const double t = k + 0.05;
    att += row(t, quat_exp(Eigen::Vector3d(0, 0, t * kDegToRad)), Eigen::Vector3d(0, 0, 1.0),
               ",0.001,NOMINAL,1234");
  }
  auto score = score_attitude(parse(att, true), parse(turning_truth(10.0), false));
  ASSERT_TRUE(score.ok());
  EXPECT_EQ(score->exact_matches, 0U);
  EXPECT_EQ(score->interpolated, 100U);  // 0.05 … 99.05
  EXPECT_EQ(score->outside_truth, 11U);  // 100.05 … 110.05
  EXPECT_LT(score->max_total_deg, 1e-9);
}

// A tolerance matches rows whose times differ by rounding: 1e-7 s apart, tolerance 1e-6 s.
TEST(ScoreMetrics, TimeToleranceMatchesRoundedTimes) {
  std::string att = kAttHeader;
  for (int k = 0; k <= 100; ++k) {
    const double t = k + 1e-7;
    att += row(t, quat_exp(Eigen::Vector3d(0, 0, k * kDegToRad)), Eigen::Vector3d(0, 0, 1.0),
               ",0.001,NOMINAL,1234");
  }
  auto score = score_attitude(parse(att, true), parse(turning_truth(1.0), false));
  ASSERT_TRUE(score.ok());
  EXPECT_EQ(score->exact_matches, 101U);
  EXPECT_LT(score->max_total_deg, 1e-9);
}

TEST(ScoreMetrics, NoOverlapIsBadInput) {
  std::string att =
      std::string(kAttHeader) + row(500, Quaternion::Identity(), Eigen::Vector3d::Zero(), ",0,NOMINAL,1234");
  auto score = score_attitude(parse(att, true), parse(turning_truth(1.0), false));
  ASSERT_FALSE(score.ok());
  EXPECT_NE(score.error().message.find("no row lies within the time span"), std::string::npos);
}

struct BadCase {
  std::string text;
  std::string expected;  // part of the message
};

TEST(ScoreInput, BadInputNamesFileLineAndColumn) {
  const std::string ok_row = row(0, Quaternion::Identity(), Eigen::Vector3d::Zero(), ",0.1,NOMINAL,1234");
  const BadCase cases[] = {
      {"time_s,qw,qx,qy,qz,wx_dps,wy_dps,sigma_deg\n", "mem.csv:1: header: no column 'wz_dps'"},
      {"time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,mode\n0,1,0,0,0,0,0,0,NOMINAL\n", "no column 'sigma_deg'"},
      {std::string(kAttHeader) + ok_row + ok_row, "mem.csv:3: column 'time_s': time not increasing"},
      {std::string(kAttHeader) + "0,0.5,0,0,0,0,0,0,0.1,NOMINAL,1234\n",
       "mem.csv:2: column 'qw': quaternion norm"},
      {std::string(kAttHeader) + "0,1,0,0,0,0,0,0,-0.1,NOMINAL,1234\n",
       "mem.csv:2: column 'sigma_deg': a 1σ"},
      {std::string(kAttHeader) + "0,1,0,0,0,,0,0,0.1,NOMINAL,1234\n", "mem.csv:2: column 'wx_dps': empty"},
      {std::string(kAttHeader) + "0,1,0,0,0,inf,0,0,0.1,NOMINAL,1234\n",
       "mem.csv:2: column 'wx_dps': not a finite"},
      {std::string(kAttHeader) + "0,1,0,0,0,x,0,0,0.1,NOMINAL,1234\n",
       "mem.csv:2: column 'wx_dps': 'x' is not a number"},
      {kAttHeader, "mem.csv: no rows"},
  };
  for (const BadCase& c : cases) {
    auto s = parse_attitude_series(c.text, "mem.csv", true);
    ASSERT_FALSE(s.ok()) << c.text;
    EXPECT_NE(s.error().message.find(c.expected), std::string::npos) << s.error().message;
  }
}

// ---- the command ----

struct Files {
  test::TempDir dir;
  std::string att = dir.file("att.csv");
  std::string truth = dir.file("truth.csv");
  Files() {
    std::string text = kAttHeader;
    for (int k = 0; k <= 100; ++k) {
      const Quaternion q =
          quat_exp(Eigen::Vector3d(0, 0, k * kDegToRad)) * quat_exp(Eigen::Vector3d(1e-5, 0, 0));
      text += row(k, q, Eigen::Vector3d(0, 0, 1.0), ",0.001,NOMINAL,1234");
    }
    test::write_file(att, text);
    test::write_file(truth, turning_truth(1.0));
  }
};

int line_count(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

TEST(ScoreCli, BadInputExitsTwoWithOneLine) {
  Files f;
  test::write_file(f.dir.file("bad.csv"), std::string(kAttHeader) + "0,1,0,0,0,0,0,0,-1,NOMINAL,1234\n");
  const auto bad = run_tetra("score " + f.dir.file("bad.csv") + " " + f.truth);
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_EQ(line_count(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("bad.csv:2: column 'sigma_deg'"), std::string::npos) << bad.err;
  const auto axis = run_tetra("score " + f.att + " " + f.truth + " --axis 0,0");
  EXPECT_EQ(axis.exit_status, 2);
  EXPECT_NE(axis.err.find("--axis"), std::string::npos) << axis.err;
  const auto missing = run_tetra("score " + f.att + " " + f.dir.file("none.csv"));
  EXPECT_EQ(missing.exit_status, 2);
  EXPECT_EQ(line_count(missing.err), 1) << missing.err;
}

TEST(ScoreCli, NeverOverwritesAnInput) {
  Files f;
  const std::string before = test::read_file(f.att);
  const auto r = run_tetra("score " + f.att + " " + f.truth + " --json " + f.att);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--json"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_file(f.att), before);
  const auto p = run_tetra("score " + f.att + " " + f.truth + " --plot " + f.truth);
  EXPECT_EQ(p.exit_status, 2);
  EXPECT_EQ(test::read_file(f.truth), turning_truth(1.0));
}

TEST(ScoreCli, WritesReportJsonAndPlot) {
  Files f;
  const auto r = run_tetra("score " + f.att + " " + f.truth + " --axis z --json " + f.dir.file("s.json") +
                           " --plot " + f.dir.file("s.png"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("integrated angle about z: 100.00 deg (truth 100.00 deg)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("total sigma_deg"), std::string::npos) << r.out;
  const std::string json = test::read_file(f.dir.file("s.json"));
  EXPECT_NE(json.find("\"nees\""), std::string::npos);
  EXPECT_NE(json.find("\"provenance\""), std::string::npos);
  const std::string png = test::read_file(f.dir.file("s.png"));
  ASSERT_GT(png.size(), 8U);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

// The seed experiment (README, docs/fdi_validation.md) by commands alone: calibrate from simulated turntable
// data, replay the lab orbit, and `tetra score --axis y` prints the integrated angle: 360 ± 0.5° (the
// requirement; measured 359.96°); the truth rates give 0.06 deg/s × 5999.2 s = 359.95° (the last row is one
// step before the turn closes).
TEST(ScoreCli, SeedExperimentAngleIsPrintedByTheCommand) {
  test::TempDir dir;
  const auto d = [&](const char* name) { return dir.file(name); };
  ASSERT_EQ(run_tetra("sim turntable -o " + d("tt.csv")).exit_status, 0);
  ASSERT_EQ(run_tetra("calibrate " + d("tt.csv") + " --latitude -23.2 -o " + d("cal.yaml")).exit_status, 0);
  ASSERT_EQ(run_tetra("sim lab-orbit -o " + d("lab.csv") + " --truth " + d("truth.csv")).exit_status, 0);
  ASSERT_EQ(run_tetra("replay " + d("lab.csv") + " --calibration " + d("cal.yaml") +
                      " --latitude -23.2 --attitude " + d("att.csv") + " --events " + d("ev.jsonl"))
                .exit_status,
            0);
  const auto r = run_tetra("score " + d("att.csv") + " " + d("truth.csv") + " --axis y");
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string key = "integrated angle about y: ";
  const auto at = r.out.find(key);
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(at + key.size())), 360.0, 0.5) << r.out;
  EXPECT_NE(r.out.find("(truth 359.9"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace tetra
