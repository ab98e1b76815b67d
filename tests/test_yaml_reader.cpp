// The shared YAML reading helpers: every error starts "FILE:LINE: " and names the field by its path.
#include <gtest/gtest.h>

#include "tetra/core/yaml_reader.hpp"

namespace tetra {
namespace {

TEST(YamlReader, UnknownKeyNamesItsLineAndListsAllowedKeysInOrder) {
  const YamlReader yaml{"f.yaml"};
  const YAML::Node root = YAML::Load("a: 1\nnoise:\n  arw: 2\n  bogus: 3\n");
  EXPECT_TRUE(yaml.check_keys(root, {"a", "noise"}, "").ok());
  const auto st = yaml.check_keys(root["noise"], {"arw", "bi"}, "gyros[0].noise");
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, "f.yaml:4: gyros[0].noise: unknown key 'bogus' (allowed: arw, bi)");
  const auto root_st = yaml.check_keys(root, {"noise"}, "");
  ASSERT_FALSE(root_st.ok());
  EXPECT_EQ(root_st.error().message, "f.yaml:1: unknown key 'a' (allowed: noise)");
  const auto not_map = yaml.check_keys(root["a"], {"x"}, "a");
  ASSERT_FALSE(not_map.ok());
  EXPECT_EQ(not_map.error().message, "f.yaml:1: a: expected a mapping");
}

TEST(YamlReader, NumbersMustBeFiniteNumbers) {
  const YamlReader yaml{"n.yaml"};
  const YAML::Node root = YAML::Load("x: 2.5\ny: abc\nz: .inf\nw: [1]\nnull_key: ~\n");
  const auto x = yaml.required_number(root, "x", "");
  ASSERT_TRUE(x.ok());
  EXPECT_EQ(*x, 2.5);  // exact: 2.5 is representable
  const auto y = yaml.required_number(root, "y", "g");
  ASSERT_FALSE(y.ok());
  EXPECT_EQ(y.error().message, "n.yaml:2: g.y: 'abc' is not a number");
  const auto z = yaml.number(root["z"], "z");
  ASSERT_FALSE(z.ok());
  EXPECT_EQ(z.error().message, "n.yaml:3: z: '.inf' is not a number");  // plain decimal numbers only
  const auto w = yaml.number(root["w"], "w");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().message, "n.yaml:4: w: '?' is not a number");
  const auto missing = yaml.required_number(root, "v", "g");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().message, "n.yaml:1: g: missing key 'v'");

  const auto absent = yaml.optional_number(root, "v", "");
  ASSERT_TRUE(absent.ok());
  EXPECT_FALSE(absent->has_value());
  const auto null_value = yaml.optional_number(root, "null_key", "");
  ASSERT_TRUE(null_value.ok());
  EXPECT_FALSE(null_value->has_value());
  const auto present = yaml.optional_number(root, "x", "");
  ASSERT_TRUE(present.ok());
  EXPECT_EQ(present->value_or(0.0), 2.5);
  EXPECT_FALSE(yaml.optional_number(root, "y", "").ok());
}

// Whole numbers, seeds and booleans say what they expect and what they got (yaml-cpp's as<T>() said only
// "bad conversion"); a long value is cut in the message.
TEST(YamlReader, TypedValuesNameTheTypeExpected) {
  const YamlReader yaml{"t.yaml"};
  const YAML::Node root =
      YAML::Load("a: 7\nb: -1\nc: 1.5\nd: maybe\ne: 18446744073709551615\nf: [1]\ng: 0x10\n");
  EXPECT_EQ(yaml.integer(root["a"], "a", 1, 32).value(), 7);
  EXPECT_EQ(yaml.integer(root["b"], "b", 1, 32).error().message,
            "t.yaml:2: b: expected a whole number from 1 to 32, got '-1'");
  EXPECT_EQ(yaml.integer(root["c"], "c", 1, 32).error().message,
            "t.yaml:3: c: expected a whole number from 1 to 32, got '1.5'");
  EXPECT_EQ(yaml.integer(root["g"], "g", 0, 100).error().message,
            "t.yaml:7: g: expected a whole number from 0 to 100, got '0x10'");
  EXPECT_EQ(yaml.unsigned_integer(root["e"], "e").value(), UINT64_MAX);
  EXPECT_EQ(yaml.unsigned_integer(root["b"], "seeds[0]").error().message,
            "t.yaml:2: seeds[0]: expected a whole number from 0 to 18446744073709551615, got '-1'");
  EXPECT_EQ(yaml.unsigned_integer(root["f"], "f").error().message,
            "t.yaml:6: f: expected a whole number from 0 to 18446744073709551615, got a list or a mapping");
  EXPECT_EQ(yaml.boolean(YAML::Load("true"), "x").value(), true);
  EXPECT_EQ(yaml.boolean(root["d"], "fault_free").error().message,
            "t.yaml:4: fault_free: expected true or false, got 'maybe'");
  const YAML::Node long_value = YAML::Load("v: " + std::string(100, '9') + "\n");
  EXPECT_EQ(yaml.integer(long_value["v"], "v", 0, 1).error().message,
            "t.yaml:1: v: expected a whole number from 0 to 1, got '" + std::string(40, '9') + "...'");
  try {
    (void)root["d"].as<int>();
    FAIL() << "yaml-cpp converted 'maybe' to an int";
  } catch (const YAML::Exception& e) {
    EXPECT_EQ(yaml.error(e, "k").message, "t.yaml:4: k: a value of the wrong type (bad conversion)");
  }
}

TEST(YamlReader, Vector3NeedsThreeFiniteNumbers) {
  const YamlReader yaml{"v.yaml"};
  const YAML::Node root = YAML::Load("a: [1, -2, 0.5]\nb: [1, 2]\nc: [1, x, 3]\n");
  const auto a = yaml.required_vector3(root, "a", "g");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(*a, Eigen::Vector3d(1.0, -2.0, 0.5));  // exact: small binary fractions
  const auto b = yaml.required_vector3(root, "b", "g");
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error().message, "v.yaml:2: g.b: expected [x, y, z]");
  const auto c = yaml.vector3(root["c"], "c");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().message, "v.yaml:3: c[1]: 'x' is not a number");
}

TEST(YamlReader, SyntaxErrorsCarryTheLine) {
  const YamlReader yaml{"s.yaml"};
  try {
    (void)YAML::Load("a: 1\nb: [unclosed\n");
    FAIL() << "yaml-cpp accepted an unclosed flow sequence";
  } catch (const YAML::Exception& e) {
    const std::string message = yaml.error(e, "YAML").message;
    EXPECT_EQ(message.rfind("s.yaml:", 0), 0U) << message;
    EXPECT_NE(message.find(": YAML: "), std::string::npos) << message;
  }
}

TEST(YamlReader, OneDocumentAndNoHangOnMalformedText) {
  // A second document is refused with its line; the inputs the fuzzers found hanging yaml-cpp's LoadAll (a
  // lone comma, ",][") come back at once (ctest's timeout is the bound).
  const YamlReader yaml{"d.yaml"};
  const auto two = yaml.load("a: 1\n---\nb: 2\n");
  ASSERT_FALSE(two.ok());
  EXPECT_NE(two.error().message.find("d.yaml:2: a second YAML document"), std::string::npos)
      << two.error().message;
  EXPECT_FALSE(yaml.load("a: 1\n...\nb: 2\n").ok());
  EXPECT_TRUE(yaml.load("---\na: 1\n...\n").ok());
  EXPECT_TRUE(yaml.load("# comment\n---\na: 1\n").ok());
  for (const char* text : {",", ",][", ",# "}) (void)yaml.load(text);
}

TEST(YamlReader, TextMustBeUtf8) {
  // Names round-trip through every writer only if they are text: a stray byte is refused by name and line.
  const YamlReader yaml{"u.yaml"};
  const auto doc = yaml.load("unit: tetr\xe1-1\nok: t\xc3\xa9tra\n");
  ASSERT_TRUE(doc.ok());
  const auto bad = yaml.text((*doc)["unit"], "unit");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "u.yaml:1: unit: expected UTF-8 text");
  EXPECT_EQ(yaml.text((*doc)["ok"], "ok").value(), "t\xc3\xa9tra");
}

}  // namespace
}  // namespace tetra
