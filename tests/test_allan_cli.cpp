// `tetra allan` end to end: outputs of docs/interfaces.md §2.6, calibration in and out, and the bad-input
// contract (exit 2 with one line naming the reason).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"

namespace tetra {
namespace {

constexpr double kN = 3e-5;  // [deg/√s] white rate noise of the synthetic logs (seed Table 6 level)

// A static log of `gyros` gyros at 100 Hz with white rate noise kN around `offset_dps`; in volts
// through `cal` when given (g = s·rate + β), else in deg/s. Every 50th sample of gyro 1 is missing
// when `gaps`.
std::string make_log(std::size_t samples, int gyros, const Calibration* cal, bool gaps = false,
                     unsigned seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, kN / std::sqrt(0.01));
  std::string text = cal ? "" : "# units=dps\n";
  text += "time_s";
  for (int g = 1; g <= gyros; ++g) text += ",g" + std::to_string(g);
  text += '\n';
  for (std::size_t i = 0; i < samples; ++i) {
    append_fixed(text, static_cast<double>(i) * 0.01, 2);
    for (int g = 0; g < gyros; ++g) {
      text += ',';
      const double rate = 4e-3 + gauss(rng);
      if (gaps && g == 0 && i % 50 == 7) continue;
      const auto& gc = cal ? cal->gyros[static_cast<std::size_t>(g)] : GyroCalibration{};
      append_double(text, cal ? gc.scale_factor_V_per_dps * rate + gc.bias_V : rate);
    }
    text += '\n';
  }
  return text;
}

// The number after "KEY": in a one-line-per-gyro JSON text, for the gyro line with "id": ID.
double json_number(const std::string& json, int id, const std::string& key) {
  const auto line_at = json.find("{\"id\": " + std::to_string(id) + ",");
  if (line_at == std::string::npos) return NAN;
  const auto k = json.find("\"" + key + "\": ", line_at);
  if (k == std::string::npos) return NAN;
  return std::strtod(json.c_str() + k + key.size() + 4, nullptr);
}

// One line on stderr, exit 2, naming the reason.
void expect_bad_input(const test::CommandResult& r, const std::string& reason) {
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find(reason), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(AllanCli, CsvJsonAndTable) {
  test::TempDir dir;
  test::write_file(dir.file("log.csv"), make_log(30000, 2, nullptr));
  const auto r = test::run_tetra("allan " + dir.file("log.csv") + " --csv " + dir.file("a.csv") + " --json " +
                                 dir.file("a.json") + " 2>/dev/null");
  ASSERT_EQ(r.exit_status, 0) << r.err;
  // The table: Table 6 columns, NO for the terms white noise does not show.
  EXPECT_NE(r.out.find("N [deg/√s]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("N [deg/√h]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("NO"), std::string::npos) << r.out;
  // CSV of §2.6 for both gyros.
  auto csv = read_csv(dir.file("a.csv"));
  ASSERT_TRUE(csv.ok()) << csv.error().message;
  EXPECT_EQ(csv->columns, (std::vector<std::string>{"gyro", "tau_s", "adev", "adev_lo", "adev_hi", "n"}));
  ASSERT_GT(csv->rows, 60U);  // ≈ 10 per decade from 0.01 s to 150 s, two gyros
  for (std::size_t row = 0; row < csv->rows; ++row) {
    EXPECT_LE(csv->cell(row, 3), csv->cell(row, 2));
    EXPECT_GE(csv->cell(row, 4), csv->cell(row, 2));
  }
  EXPECT_EQ(csv->cell(0, 0), 1.0);
  EXPECT_EQ(csv->cell(csv->rows - 1, 0), 2.0);
  // JSON: units, N within 5 % of the truth (30 000 samples: its scatter is ~1 %), K null.
  const std::string json = test::read_file(dir.file("a.json"));
  EXPECT_NE(json.find("\"units\": \"deg/s\""), std::string::npos) << json;
  EXPECT_NEAR(json_number(json, 1, "N"), kN, 0.05 * kN) << json;
  EXPECT_NEAR(json_number(json, 2, "N"), kN, 0.05 * kN) << json;
  EXPECT_NE(json.find("\"K\": null"), std::string::npos) << json;
}

// Volts through a calibration become deg/s; --update-calibration writes the noise keys, which read
// back through the calibration reader (N within 5 %, not-observed terms absent).
TEST(AllanCli, CalibrationInAndUpdate) {
  test::TempDir dir;
  Calibration cal = seed_as_built_unit();
  for (auto& g : cal.gyros) g.noise.reset();
  ASSERT_TRUE(write_calibration(dir.file("cal.yaml"), cal).ok());
  test::write_file(dir.file("log.csv"), make_log(30000, 4, &cal));
  const auto r = test::run_tetra("allan " + dir.file("log.csv") + " --calibration " + dir.file("cal.yaml") +
                                 " --update-calibration --gyro 2 --json " + dir.file("a.json"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string json = test::read_file(dir.file("a.json"));
  EXPECT_NE(json.find("\"units\": \"deg/s\""), std::string::npos) << json;
  EXPECT_EQ(json.find("\"id\": 1,"), std::string::npos) << "only gyro 2 was asked for";
  auto updated = read_calibration(dir.file("cal.yaml"));
  ASSERT_TRUE(updated.ok()) << updated.error().message;
  EXPECT_FALSE(updated->gyros[0].noise.has_value());
  ASSERT_TRUE(updated->gyros[1].noise.has_value());
  ASSERT_TRUE(updated->gyros[1].noise->arw_dps_rtHz.has_value());
  EXPECT_NEAR(*updated->gyros[1].noise->arw_dps_rtHz, kN, 0.05 * kN);
  EXPECT_FALSE(updated->gyros[1].noise->rate_random_walk_dps_per_rts.has_value());

  // Without a calibration the same log is analysed in volts and says so.
  const auto v = test::run_tetra("allan " + dir.file("log.csv") + " --gyro 1 --json " + dir.file("v.json"));
  ASSERT_EQ(v.exit_status, 0) << v.err;
  EXPECT_NE(test::read_file(dir.file("v.json")).find("\"units\": \"V\""), std::string::npos);
  EXPECT_NE(v.out.find("need rates in deg/s"), std::string::npos) << v.out;
}

// Empty cells are gaps: counted as absent, and N unchanged within 5 %.
TEST(AllanCli, GapsAreCountedAndHarmless) {
  test::TempDir dir;
  test::write_file(dir.file("log.csv"), make_log(30000, 1, nullptr, true));
  const auto r = test::run_tetra("allan " + dir.file("log.csv") + " --json " + dir.file("a.json"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string json = test::read_file(dir.file("a.json"));
  EXPECT_EQ(json_number(json, 1, "absent"), 600.0) << json;  // every 50th of 30 000
  EXPECT_NEAR(json_number(json, 1, "N"), kN, 0.05 * kN) << json;
}

TEST(AllanCli, PlotIsAPng) {
  if (test::run_shell("command -v gnuplot").exit_status != 0) GTEST_SKIP() << "gnuplot not installed";
  test::TempDir dir;
  test::write_file(dir.file("log.csv"), make_log(5000, 2, nullptr));
  const auto r = test::run_tetra("allan " + dir.file("log.csv") + " --plot " + dir.file("a.png"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string png = test::read_file(dir.file("a.png"));
  ASSERT_GT(png.size(), 1000U);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

TEST(AllanCli, BadInputExitsTwoWithAReason) {
  test::TempDir dir;
  test::write_file(dir.file("nogyro.csv"), "time_s\n0\n0.01\n");
  expect_bad_input(test::run_tetra("allan " + dir.file("nogyro.csv")), "no gyro columns");

  test::write_file(dir.file("text.csv"), "time_s,g1\n0,1\n0.01,abc\n");
  expect_bad_input(test::run_tetra("allan " + dir.file("text.csv")), "text.csv:3: column 'g1'");

  test::write_file(dir.file("one.csv"), "# units=dps\ntime_s,g1\n0,1\n");
  expect_bad_input(test::run_tetra("allan " + dir.file("one.csv")), "1 sample");

  test::write_file(dir.file("jitter.csv"),
                   "# units=dps\ntime_s,g1\n0,1\n0.01,2\n0.02,1\n0.035,2\n0.045,1\n0.055,2\n");
  expect_bad_input(test::run_tetra("allan " + dir.file("jitter.csv")), "jitter.csv:6: column 'time_s'");
  expect_bad_input(test::run_tetra("allan " + dir.file("jitter.csv")), "non-uniform sampling");

  test::write_file(dir.file("log.csv"), make_log(1000, 4, nullptr));
  expect_bad_input(test::run_tetra("allan " + dir.file("log.csv") + " --taus=-1"), "not positive");
  expect_bad_input(test::run_tetra("allan " + dir.file("log.csv") + " --taus 0.1,-2"), "not positive");
  expect_bad_input(test::run_tetra("allan " + dir.file("log.csv") + " --taus 100"),
                   "exceeds half the record");
  expect_bad_input(test::run_tetra("allan " + dir.file("log.csv") + " --gyro 5"),
                   "--gyro 5: the log has gyros 1..4");
  expect_bad_input(test::run_tetra("allan " + dir.file("log.csv") + " --taus 0.1,x"), "--taus: 'x' is not");
  expect_bad_input(test::run_tetra("allan " + dir.file("log.csv") + " --update-calibration"),
                   "needs --calibration");
  expect_bad_input(test::run_tetra("allan " + dir.file("missing.csv")), "cannot open");
  // The library names the argument (Error::subject); the command words it with its option.
  expect_bad_input(test::run_tetra("allan " + dir.file("log.csv") + " --taus 100"), "allan: --taus: ");
  test::write_file(dir.file("silent.csv"), "# units=dps\ntime_s,g1,g2\n0,1,\n0.1,1,\n0.2,1,\n0.3,1,\n");
  expect_bad_input(
      test::run_tetra("allan " + dir.file("silent.csv")),
      "gyro 2: 0 valid sample(s): an Allan variance needs at least 2 (--gyro N analyses the others "
      "alone)");
  // A finite value too large to square (1e300) is named as such: it was blamed on gaps the log has not.
  test::write_file(dir.file("huge.csv"),
                   "# units=dps\ntime_s,g1\n0,1\n0.1,2\n0.2,1e300\n0.3,1\n0.4,2\n0.5,1\n");
  expect_bad_input(test::run_tetra("allan " + dir.file("huge.csv") + " --taus 0.1"),
                   "the values are too large to square (beyond about 1e150), not gaps");
  EXPECT_EQ(test::run_tetra("allan --help").exit_status, 0);
}

}  // namespace
}  // namespace tetra
