// Regressions found by fuzzing the parsers (tests/fuzz/): each input below once crashed a reader or
// produced a multi-line error. A CLI prints an error as one line on stderr, so a message that quotes
// a control character from the input must escape it.
#include <gtest/gtest.h>

#include <string>

#include "tetra/core/calibration_file.hpp"
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
