// Regressions found by fuzzing the parsers (tests/fuzz/): each input below once crashed a reader or
// produced a multi-line error. A CLI prints an error as one line on stderr, so a message that quotes
// a control character from the input must escape it.
#include <gtest/gtest.h>

#include <string>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/result.hpp"
#include "tetra/core/turntable_log.hpp"

namespace tetra {
namespace {

bool one_line(const std::string& message) {
  return !message.empty() && message.find('\n') == std::string::npos;
}

TEST(ReliabilityParsers, GyroColumnNumberBeyondIntIsAnErrorNotACrash) {
  // std::stoi threw std::out_of_range on this header and terminated the program.
  const auto log = parse_gyro_log("time_s,g1,g29999999999999999999999\n0,1,2\n", "huge.csv");
  ASSERT_FALSE(log.ok());
  EXPECT_NE(log.error().message.find("huge.csv:1"), std::string::npos) << log.error().message;
  EXPECT_NE(log.error().message.find("g29999999999999999999999"), std::string::npos) << log.error().message;
}

TEST(ReliabilityParsers, TimesBeyondTheNanosecondRangeAreRefusedNamingTheLine) {
  // 1e10 s does not fit 64-bit nanoseconds: every epoch after the first was rejected with exit 0.
  const auto log = parse_gyro_log("time_s,g1\n10000000000.00,1\n10000000000.01,2\n", "big.csv");
  ASSERT_FALSE(log.ok());
  EXPECT_NE(log.error().message.find("big.csv:2: column 'time_s': time 1e+10 s is beyond"), std::string::npos)
      << log.error().message;
  EXPECT_TRUE(parse_gyro_log("time_s,g1\n8999999999.99,1\n8999999999.991,2\n", "ok.csv").ok());
  EXPECT_TRUE(log_time_problem(-9.1e9).has_value());
}

TEST(ReliabilityParsers, DecimalCommaInAMetadataCommentStaysInTheValue) {
  Metadata meta;
  parse_metadata_comment(" latitude_deg=-23,2", meta);
  ASSERT_EQ(meta.size(), 1U);
  EXPECT_EQ(meta[0].second, "-23,2");  // its reader refuses it; it was read as -23
  meta.clear();
  parse_metadata_comment(" a=1,b=2 c=3", meta);  // commas between key=value pairs still separate them
  ASSERT_EQ(meta.size(), 3U);
  EXPECT_EQ(meta[0].second, "1");
  EXPECT_EQ(meta[1].second, "2");
}

TEST(ReliabilityParsers, DenormalScaleFactorIsRefusedNamingTheKey) {
  // 1e-320 is a denormal: its reciprocal overflows, and replay wrote NaN sigma rows with exit 0.
  std::string text = format_calibration(seed_as_built_unit());
  const std::size_t at =
      text.find("scale_factor_V_per_dps: ") + std::string("scale_factor_V_per_dps: ").size();
  text.replace(at, text.find('\n', at) - at, "1e-320");
  const auto cal = parse_calibration(text, "den.yaml");
  ASSERT_FALSE(cal.ok());
  EXPECT_NE(cal.error().message.find(
                "gyros[0].scale_factor_V_per_dps: must be a number with magnitude in [1e-9, 1e9]"),
            std::string::npos)
      << cal.error().message;
  EXPECT_NE(cal.error().message.find("den.yaml:"), std::string::npos);
}

TEST(ReliabilityParsers, DuplicateGyroColumnIsRejected) {
  // Found by fuzzing; the CSV reader now refuses any repeated header name.
  const auto log = parse_gyro_log("time_s,g1,g1\n0,1,2\n", "dup.csv");
  ASSERT_FALSE(log.ok());
  EXPECT_NE(log.error().message.find("column 'g1' appears twice"), std::string::npos) << log.error().message;
}

TEST(ReliabilityParsers, DuplicateTurntableColumnIsRejected) {
  const auto log =
      parse_turntable_log("sequence,time_s,inner_deg,outer_deg,g1,g2,g3,g1\n1,0,0,0,1,2,3,4\n", "dup.csv");
  ASSERT_FALSE(log.ok());
  EXPECT_NE(log.error().message.find("column 'g1' appears twice"), std::string::npos) << log.error().message;
}

TEST(ReliabilityParsers, YamlErrorQuotingANewlineStaysOneLine) {
  // yaml-cpp's message quotes the bad escape character, here a newline.
  const auto cal = parse_calibration("unit: \"a\\\nb\"\n", "esc.yaml");
  ASSERT_FALSE(cal.ok());
  EXPECT_TRUE(one_line(cal.error().message)) << cal.error().message;
  EXPECT_NE(cal.error().message.find("esc.yaml:"), std::string::npos) << cal.error().message;
}

TEST(ReliabilityParsers, ErrorsEscapeControlCharacters) {
  EXPECT_EQ(bad_input("a\nb\r\tc\x01").message, "a\\nb\\r\\tc\\x01");
  EXPECT_EQ(failure("\x7f").message, "\\x7f");
  EXPECT_EQ(bad_input("plain text, ü").message, "plain text, ü");  // UTF-8 passes unchanged
}

}  // namespace
}  // namespace tetra
