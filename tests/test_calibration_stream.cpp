// Calibration in bounded memory: the estimators visit the turntable log in passes (never holding its
// rows) and must give the results of the whole-log estimators they replaced. The golden file
// tests/golden/calibration_results.txt holds those results, written by the whole-log estimators
// (every number in hexadecimal floating point, so every bit is compared). Re-bless only for an
// intended change of results: TETRA_BLESS=1 build/tests/test_calibration_accuracy
// --gtest_filter='CalibrationStream*'
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "calibration_test_unit.hpp"
#include "test_support.hpp"
#include "tetra/core/calibration.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/core/turntable_rows.hpp"
#include "tetra/sim/turntable.hpp"

namespace tetra {
namespace {

struct Case {
  const char* name;
  bool plan_order;  // sequences in the file in plan order
  CalibrationMethod method;
  BiasModel bias_model;
};

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      {"plan_order_sixteen", true, CalibrationMethod::kSixteen, BiasModel::kBody},
      {"plan_order_seed_bias", true, CalibrationMethod::kSixteen, BiasModel::kSeed},
      {"plan_order_batch", true, CalibrationMethod::kBatch, BiasModel::kBody},
      {"other_order_sixteen", false, CalibrationMethod::kSixteen, BiasModel::kBody},
      {"other_order_batch", false, CalibrationMethod::kBatch, BiasModel::kBody},
  };
  return all;
}

TurntableLog simulated_log(bool plan_order) {
  sim::TurntablePlan plan;  // seed plan: 6 deg/s, 1 revolution, 10 Hz, −23.2°
  if (!plan_order) plan.order = {9, 10, 1, 2, 16, 15, 5, 6, 12, 11, 3, 4, 13, 14, 8, 7};
  auto log = sim::simulate_turntable(test::white_noise_unit(), plan, plan_order ? 31 : 32);
  EXPECT_TRUE(log.ok()) << (log.ok() ? "" : log.error().message);
  return std::move(log.value());
}

CalibrationOptions options_of(const Case& c) {
  CalibrationOptions options;
  options.method = c.method;
  options.bias_model = c.bias_model;
  return options;
}

// One line per gyro: estimates, 1σ and residual RMS, each in hexadecimal floating point.
std::vector<std::string> result_lines(const Case& c, const CalibrationResult& r) {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < r.calibration.gyros.size(); ++i) {
    const auto& g = r.calibration.gyros[i];
    const auto k = static_cast<Eigen::Index>(i);
    const double v[] = {g.scale_factor_V_per_dps,
                        g.bias_V,
                        g.axis_B.x(),
                        g.axis_B.y(),
                        g.axis_B.z(),
                        g.sigma->scale_factor_V_per_dps,
                        g.sigma->bias_V,
                        g.sigma->axis.x(),
                        g.sigma->axis.y(),
                        g.sigma->axis.z(),
                        r.fit.sample_rms_V(k),
                        r.fit.sequence_rms_V(k)};
    std::string line = std::string(c.name) + " g" + std::to_string(i + 1);
    for (double x : v) {
      char buf[64];
      std::snprintf(buf, sizeof buf, " %a", x);
      line += buf;
    }
    lines.push_back(line);
  }
  return lines;
}

std::vector<std::string> all_result_lines() {
  std::vector<std::string> lines;
  for (const Case& c : cases()) {
    const TurntableLog log = simulated_log(c.plan_order);
    auto motion = analyze_turntable(log, sim::TurntablePlan{}.latitude_deg);
    EXPECT_TRUE(motion.ok()) << (motion.ok() ? "" : motion.error().message);
    auto result = calibrate(log, *motion, options_of(c));
    EXPECT_TRUE(result.ok()) << (result.ok() ? "" : result.error().message);
    for (auto& line : result_lines(c, *result)) lines.push_back(std::move(line));
  }
  return lines;
}

std::vector<double> numbers_of(const std::string& line, std::string& label) {
  std::istringstream in(line);
  std::string name, gyro, token;
  in >> name >> gyro;
  label = name + " " + gyro;
  std::vector<double> out;
  while (in >> token) out.push_back(std::strtod(token.c_str(), nullptr));
  return out;
}

const std::string kGolden = "tests/golden/calibration_results.txt";

TEST(CalibrationStream, ResultsOfTheWholeLogEstimators) {
  const std::vector<std::string> now = all_result_lines();
  const char* bless = std::getenv("TETRA_BLESS");
  if (bless != nullptr && std::strcmp(bless, "1") == 0) {
    std::ofstream out(test::source_path(kGolden));
    for (const auto& line : now) out << line << "\n";
    ASSERT_TRUE(out.good());
    return;
  }
  std::ifstream in(test::source_path(kGolden));
  std::vector<std::string> golden;
  for (std::string line; std::getline(in, line);) golden.push_back(line);
  ASSERT_EQ(golden.size(), now.size()) << kGolden;
  for (std::size_t k = 0; k < now.size(); ++k) {
    std::string label;
    std::string golden_label;
    const std::vector<double> a = numbers_of(now[k], label);
    const std::vector<double> b = numbers_of(golden[k], golden_label);
    ASSERT_EQ(label, golden_label);
    ASSERT_EQ(a.size(), b.size());
    if (label.rfind("plan_order", 0) == 0) {
      // Rows in plan order: every sum runs over the same terms in the same order as before. Every bit.
      EXPECT_EQ(now[k], golden[k]);
      continue;
    }
    // Sequences in the file out of plan order: the batch normal equations and the sample RMS now sum
    // the rows in file order, the whole-log estimators summed them in plan order. Reordering a sum of
    // 9600 rounded terms moves it by a few ulp and the 4x4 solve carries that through: 1e-12 relative
    // is the bound promised (measured: at most 1.0e-13, on an axis component of -1.5e-3 and a bias of
    // 4e-4 V, small numbers left by cancellation; the sixteen-position estimates are unchanged). The residual
    // RMS over sequence means of the batch fit is itself rounding noise here (about 1e-19 V), so its bound is
    // 1e-12 of the outputs it is computed from (0.4 V: scale factor times the 6 deg/s table rate), not of
    // itself (measured: at most 5e-18 V).
    for (std::size_t j = 0; j < a.size(); ++j) {
      const bool residual_rms = j >= 10;
      const double scale = residual_rms ? std::max(std::abs(b[j]), a[0] * 6.0) : std::abs(b[j]);
      EXPECT_LE(std::abs(a[j] - b[j]), 1e-12 * scale) << label << " value " << j;
    }
  }
}

// tetra calibrate's path: the log written to a file and visited pass by pass from its temporary binary
// copy gives every bit of the result of the log in memory, and its messages name the file's lines.
TEST(CalibrationStream, FileRowsGiveTheLogInMemorysResults) {
  test::TempDir dir;
  for (const Case& c : cases()) {
    const TurntableLog log = simulated_log(c.plan_order);
    const std::string path = dir.file(std::string(c.name) + ".csv");
    ASSERT_TRUE(write_turntable_log(path, log).ok());
    TurntableFileRows rows;
    ASSERT_TRUE(rows.open(path).ok());
    auto whole = parse_turntable_log(test::read_file(path), path);
    ASSERT_TRUE(whole.ok());
    const double latitude_deg = sim::TurntablePlan{}.latitude_deg;
    auto motion_memory = analyze_turntable(*whole, latitude_deg);
    auto motion_file = analyze_turntable(rows, latitude_deg);
    ASSERT_TRUE(motion_memory.ok() && motion_file.ok());
    auto memory = calibrate(*whole, *motion_memory, options_of(c));
    auto file = calibrate(rows, *motion_file, options_of(c));
    ASSERT_TRUE(memory.ok() && file.ok());
    EXPECT_EQ(result_lines(c, *file), result_lines(c, *memory));
    EXPECT_EQ(motion_file->sequences.front().first_line, motion_memory->sequences.front().first_line);
  }
  // A sequence that comes back: the same message, naming the same lines, from the file's passes.
  std::string text = test::read_file(dir.file("plan_order_batch.csv"));
  const std::size_t last_row = text.rfind('\n', text.size() - 2) + 1;
  std::string row = text.substr(last_row);
  row.replace(0, row.find(','), "1");
  test::write_file(
      dir.file("again.csv"),
      text + row.replace(row.find(',') + 1, row.find(',', row.find(',') + 1) - row.find(',') - 1, "1e9"));
  TurntableFileRows rows;
  ASSERT_TRUE(rows.open(dir.file("again.csv")).ok());
  auto whole = parse_turntable_log(test::read_file(dir.file("again.csv")), dir.file("again.csv"));
  ASSERT_TRUE(whole.ok());
  auto from_file = analyze_turntable(rows, 0.0);
  auto from_memory = analyze_turntable(*whole, 0.0);
  ASSERT_FALSE(from_file.ok());
  ASSERT_FALSE(from_memory.ok());
  EXPECT_EQ(from_file.error().message, from_memory.error().message);
  EXPECT_NE(from_file.error().message.find("appears again"), std::string::npos) << from_file.error().message;
}

// Without a folder for its temporary file the log cannot be visited in passes: a failure (tetra calibrate
// exits 1), not bad input, naming the folder.
TEST(CalibrationStream, NoTemporaryFolderIsAFailureNamingIt) {
  test::TempDir dir;
  ASSERT_TRUE(write_turntable_log(dir.file("tt.csv"), simulated_log(true)).ok());
  const char* before = std::getenv("TMPDIR");
  const std::string saved = before != nullptr ? before : "";
  setenv("TMPDIR", dir.file("missing").c_str(), 1);
  TurntableFileRows rows;
  const Status opened = rows.open(dir.file("tt.csv"));
  if (before != nullptr) {
    setenv("TMPDIR", saved.c_str(), 1);
  } else {
    unsetenv("TMPDIR");
  }
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.error().kind, ErrorKind::kFailure);
  EXPECT_NE(opened.error().message.find(dir.file("missing")), std::string::npos) << opened.error().message;
  EXPECT_NE(opened.error().message.find("cannot create a temporary file"), std::string::npos);
}

}  // namespace
}  // namespace tetra
