// Text tables and gyro logs (docs/interfaces.md §2, §2.2): header by name, comments, empty vs nan, errors
// that name file, line and column.
#include <cmath>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"

namespace tetra {
namespace {

TEST(Csv, ParsesCommentsMetadataEmptyAndNan) {
  const auto t =
      parse_csv("# latitude_deg=-23.2 units=V\nb, a\n1,2\n\n# mid comment\n,nan\n+3.5,-1e-3\n", "x.csv");
  ASSERT_TRUE(t.ok()) << t.error().message;
  EXPECT_EQ(t->columns.size(), 2U);
  EXPECT_EQ(*t->find_column("a"), 1U);
  EXPECT_EQ(t->meta("latitude_deg").value(), "-23.2");
  EXPECT_EQ(t->meta("units").value(), "V");
  ASSERT_EQ(t->rows, 3U);
  EXPECT_TRUE(t->is_empty(1, 0));
  EXPECT_FALSE(t->is_empty(1, 1));
  EXPECT_TRUE(std::isnan(t->cell(1, 1)));
  EXPECT_DOUBLE_EQ(t->cell(2, 0), 3.5);
  EXPECT_EQ(t->lines[2], 7U);
}

TEST(Csv, ErrorsNameFileLineAndColumn) {
  const auto bad = parse_csv("time_s,g1\n0,1\n0.1,abc\n", "log.csv");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "log.csv:3: column 'g1': 'abc' is not a number");
  const auto short_row = parse_csv("a,b\n1\n", "s.csv");
  ASSERT_FALSE(short_row.ok());
  EXPECT_NE(short_row.error().message.find("s.csv:2"), std::string::npos);
  const auto empty = parse_csv("# only a comment\n", "e.csv");
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.error().message.find("empty file"), std::string::npos);
  const auto dup = parse_csv("a,a\n", "d.csv");
  ASSERT_FALSE(dup.ok());
}

TEST(GyroLog, RoundTripIsExactAndKeepsAbsentVsInvalid) {
  test::TempDir dir;
  const std::string path = dir.file("log.csv");
  GyroLogWriter w;
  ASSERT_TRUE(w.open(path, 4, true, false, {{"seed", "3"}}).ok());
  const double v1[4] = {0.1, -2.5e-7, 1.0 / 3.0, 4};
  const std::uint8_t p1[4] = {1, 1, 1, 1};
  const double v2[4] = {0.2, std::nan(""), 0, 5};
  const std::uint8_t p2[4] = {1, 1, 0, 1};
  ASSERT_TRUE(w.write(0.0, v1, p1, std::array<double, 4>{1, 0, 0, 0}).ok());
  ASSERT_TRUE(w.write(0.1, v2, p2).ok());
  ASSERT_TRUE(w.close().ok());
  const auto log = read_gyro_log(path);
  ASSERT_TRUE(log.ok()) << log.error().message;
  EXPECT_EQ(log->gyro_count, 4);
  EXPECT_EQ(log->epochs(), 2U);
  EXPECT_EQ(log->value(0, 2), 1.0 / 3.0);  // shortest round-trip text: bit-exact
  EXPECT_TRUE(log->is_present(1, 1));
  EXPECT_TRUE(std::isnan(log->value(1, 1)));
  EXPECT_FALSE(log->is_present(1, 2));
  EXPECT_TRUE(log->has_reference);
  EXPECT_EQ(log->reference_present[0], 1);
  EXPECT_EQ(log->reference_present[1], 0);
  EXPECT_EQ(log->meta("seed").value(), "3");
}

TEST(GyroLog, RejectsMalformedLogs) {
  EXPECT_FALSE(parse_gyro_log("g1,g2\n1,2\n", "a.csv").ok());               // no time_s
  EXPECT_FALSE(parse_gyro_log("time_s\n1\n", "b.csv").ok());                // no gyros
  EXPECT_FALSE(parse_gyro_log("time_s,g1,gx\n1,2,3\n", "c.csv").ok());      // unknown column
  EXPECT_FALSE(parse_gyro_log("time_s,g1,ref_qw\n1,2,1\n", "d.csv").ok());  // partial reference set
  EXPECT_FALSE(parse_gyro_log("time_s,g1\n,2\n", "e.csv").ok());            // empty time
  const auto units = parse_gyro_log("# units=furlongs\ntime_s,g1\n0,2\n", "f.csv");
  ASSERT_FALSE(units.ok());
  EXPECT_NE(units.error().message.find("units"), std::string::npos);
  const auto dps = parse_gyro_log("# units=dps\ntime_s,g1\n0,2\n", "g.csv");
  ASSERT_TRUE(dps.ok());
  EXPECT_TRUE(dps->units_dps);
}

// Text columns (an attitude file's mode and gyros) are skipped, not parsed; every other cell stays strict.
TEST(Csv, TextColumnsAreNotParsed) {
  const std::string text = "t,mode,gyros,x\n1,NOMINAL,1;2;10,2\n2,,124,3\n";
  const auto t = parse_csv(text, "a.csv", {"mode", "gyros"});
  ASSERT_TRUE(t.ok()) << t.error().message;
  ASSERT_EQ(t->rows, 2U);
  EXPECT_TRUE(std::isnan(t->cell(0, 1)));
  EXPECT_FALSE(t->is_empty(1, 1));
  EXPECT_EQ(t->cell(1, 3), 3.0);
  EXPECT_FALSE(parse_csv(text, "a.csv").ok());  // without: 'NOMINAL' is not a number
  const auto bad = parse_csv("t,mode\nx,NOMINAL\n", "b.csv", {"mode"});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("b.csv:2: column 't'"), std::string::npos) << bad.error().message;
}

}  // namespace
}  // namespace tetra
