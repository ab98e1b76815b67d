// Library errors name the argument that was wrong (Error::subject), never a command-line option;
// the command maps the subject to its option (tetra allan, tetra score).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "test_support.hpp"
#include "tetra/core/allan.hpp"
#include "tetra/core/allan_kalibr.hpp"
#include "tetra/core/attitude_score.hpp"
#include "tetra/core/calibration.hpp"
#include "tetra/core/gyro_log.hpp"

namespace tetra {
namespace {

void expect_subject(const Error& e, const std::string& name, const std::string& value = "") {
  EXPECT_EQ(e.subject.name, name) << e.message;
  EXPECT_EQ(e.subject.value, value) << e.message;
  EXPECT_EQ(e.message.find("--"), std::string::npos) << e.message;
}

// A dps log "log.csv" of `gyros` gyros and `rows` rows at 100 Hz, every rate 1 deg/s; gyro
// `silent` (1-based, 0: none) delivers nothing.
GyroLog dps_log(int gyros, int rows, int silent = 0) {
  std::string text = "# units=dps\ntime_s";
  for (int g = 1; g <= gyros; ++g) text += ",g" + std::to_string(g);
  text += '\n';
  for (int r = 0; r < rows; ++r) {
    text += std::to_string(r) + "e-2";
    for (int g = 1; g <= gyros; ++g) text += g == silent ? "," : ",1";
    text += '\n';
  }
  auto log = parse_gyro_log(text, "log.csv");
  EXPECT_TRUE(log.ok()) << log.error().message;
  return log.ok() ? *log : GyroLog{};
}

TEST(LibraryErrors, AllanErrorsNameTheirArgument) {
  expect_subject(allan::parse_tau_spec("1,x").error(), allan::kSubjectTaus);
  expect_subject(allan::parse_tau_spec("0").error(), allan::kSubjectTaus);
  allan::TauSpec all;
  all.spacing = allan::TauSpacing::kAll;
  const Error too_slow = allan::averaging_factors(all, 100'000'000, 0.01).error();
  expect_subject(too_slow, allan::kSubjectTaus);
  EXPECT_EQ(too_slow.message.rfind("'all' on 100000000 samples", 0), 0u) << too_slow.message;
  allan::TauSpec long_tau;
  long_tau.spacing = allan::TauSpacing::kList;
  long_tau.list_s = {100.0};
  expect_subject(allan::averaging_factors(long_tau, 100, 0.01).error(), allan::kSubjectTaus);

  const GyroLog log = dps_log(4, 100);
  allan::LogAllanOptions bad_gyro;
  bad_gyro.gyros = {5};
  expect_subject(allan::analyze_gyro_log(log, bad_gyro).error(), allan::kSubjectGyros, "5");
  allan::LogAllanOptions too_long;  // a τ no gyro can have: its subject stays the τ list
  too_long.allan.taus = long_tau;
  const Error per_gyro = allan::analyze_gyro_log(log, too_long).error();
  expect_subject(per_gyro, allan::kSubjectTaus);
  EXPECT_NE(per_gyro.message.find("log.csv: gyro 1: "), std::string::npos) << per_gyro.message;
}

TEST(LibraryErrors, OneGyroOfSeveralNamesTheOthersAsAWayRound) {
  const GyroLog log = dps_log(2, 100, 2);
  const Error both = allan::analyze_gyro_log(log, {}).error();
  expect_subject(both, allan::kSubjectOtherGyros);
  EXPECT_NE(both.message.find("log.csv: gyro 2: "), std::string::npos) << both.message;
  allan::LogAllanOptions alone;
  alone.gyros = {2};
  expect_subject(allan::analyze_gyro_log(log, alone).error(), "");  // no other gyro to analyse
}

TEST(LibraryErrors, OutputsOfTheAllanAnalysisNameTheirPurpose) {
  allan::LogAllan volts;
  volts.units = "V";
  Calibration cal;
  expect_subject(allan::update_calibration_noise(cal, volts).error(), allan::kSubjectNoiseUpdate);
  expect_subject(allan::kalibr_gyro_noise(volts, cal).error(), allan::kSubjectKalibr);
}

TEST(LibraryErrors, ScoreOptionsNameTheirField) {
  ScoreOptions axis;
  axis.axis_B = Eigen::Vector3d(1.0, 1.0, 0.0);
  expect_subject(score_attitude({}, {}, axis).error(), "axis_B");
  ScoreOptions tolerance;
  tolerance.time_tolerance_s = -1.0;
  expect_subject(score_attitude({}, {}, tolerance).error(), "time_tolerance_s");
}

TEST(LibraryErrors, DescribeWordsTheSubjectInTheLibrarysNames) {
  EXPECT_EQ(describe(bad_input({"gyros", "5"}, "the log has gyros 1..4")), "gyros 5: the log has gyros 1..4");
  EXPECT_EQ(describe(bad_input({"taus"}, "bad")), "taus: bad");
  EXPECT_EQ(describe(bad_input("file.csv:3: bad")), "file.csv:3: bad");
}

// No string literal in the libraries' sources names an option ("--name"). Two texts that are not
// errors name the command that made their output, on purpose: the Allan table's hint and the Kalibr
// file's header comment.
TEST(LibraryErrors, NoLibrarySourceNamesACommandLineOption) {
  const std::set<std::string> allowed = {
      "\"\\n(customary units deg/√h, deg/h, ... need rates in deg/s: give --calibration CAL.yaml)\\n\"",
      "\"Kalibr IMU configuration written by tetra allan --kalibr (docs/allan.md)\""};
  const std::regex literal(R"("([^"\\]|\\.)*--[a-z]([^"\\]|\\.)*")");
  const std::filesystem::path root = TETRA_SOURCE_DIR;
  int files = 0;
  for (const char* dir : {"core", "fdi", "sim"}) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root / dir)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".cpp" && ext != ".hpp") continue;
      ++files;
      std::ifstream in(entry.path());
      std::string line;
      for (int number = 1; std::getline(in, line); ++number) {
        const auto code = line.substr(0, line.find("//"));
        for (std::sregex_iterator m(code.begin(), code.end(), literal), end; m != end; ++m) {
          EXPECT_TRUE(allowed.count(m->str()) == 1)
              << entry.path().string() << ":" << number << ": " << m->str();
        }
      }
    }
  }
  EXPECT_GT(files, 50);  // the scan saw the libraries
}

}  // namespace
}  // namespace tetra
