// JSON pieces written in events and monitor lines: every string must stay one valid JSON literal.
#include <cmath>

#include <gtest/gtest.h>

#include "tetra/core/json.hpp"

namespace tetra {
namespace {

TEST(Json, StringEscapesQuotesBackslashesAndControlCharacters) {
  std::string out;
  const std::string text = std::string("a\"b\\c\nd\te\x01") + "f\x1f";  // \x01 and \x1f: control characters
  append_json_string(out, text);
  EXPECT_EQ(out, R"("a\"b\\c\nd\te\u0001f\u001f")");
}

TEST(Json, NumbersRoundTripAndNonFiniteIsNull) {
  std::string out;
  append_json_number(out, 0.1);
  out += ' ';
  append_json_number(out, std::nan(""));
  out += ' ';
  append_json_number(out, -INFINITY);
  EXPECT_EQ(out, "0.1 null null");
}

}  // namespace
}  // namespace tetra
