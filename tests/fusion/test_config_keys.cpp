// The `pipeline:` keys' one table (fdi/src/config_keys.cpp): the example file and docs/fdi.md name every
// key and no other, every range refuses a value just outside it with a message naming the key, and the
// listing (tetra replay --config-keys) shows each key's unit, range and default. Its second section, the
// fixed design constants: listed with their unit and value, named in docs/fdi.md, refused in a file.
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "config_keys.hpp"
#include "test_support.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi {
namespace {

using Edge = ConfigLimit::Edge;

std::set<std::string> table_names() {
  std::set<std::string> names;
  for (const auto& key : config_keys()) names.insert(key.name);
  return names;
}

std::set<std::string> constant_names() {
  std::set<std::string> names;
  for (const auto& constant : design_constants()) names.insert(constant.name);
  return names;
}

// The keys a text names: in YAML lines "  key:" or commented "  # key:"; in Markdown rows "| `key` |".
std::set<std::string> names_matching(const std::string& text, const std::regex& pattern) {
  std::set<std::string> names;
  std::istringstream in(text);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_search(line, m, pattern)) names.insert(m[1].str());
  }
  return names;
}

void expect_same_names(const std::set<std::string>& named, const std::set<std::string>& table,
                       const std::string& where) {
  for (const auto& name : table) EXPECT_EQ(named.count(name), 1U) << where << " does not name " << name;
  for (const auto& name : named) EXPECT_EQ(table.count(name), 1U) << where << " names unknown " << name;
}
void expect_same_keys(const std::set<std::string>& named, const std::string& where) {
  expect_same_names(named, table_names(), where);
}

TEST(ConfigKeys, TheExampleFileNamesEveryKeyAndNoOther) {
  const std::string text = test::read_file(test::source_path("examples/fusion.yaml"));
  expect_same_keys(names_matching(text, std::regex(R"(^  (?:# )?([A-Za-z0-9_]+):)")), "examples/fusion.yaml");
  // It reads back as the defaults, and it is the file the table writes (tetra replay --config-example).
  const auto read = read_pipeline_config(test::source_path("examples/fusion.yaml"));
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_EQ(describe(*read), describe(PipelineConfig{}));
  EXPECT_EQ(text, example_config()) << "rewrite it: tetra replay --config-example > examples/fusion.yaml";
}

TEST(ConfigKeys, TheDocsConfigurationSectionNamesEveryKeyAndNoOther) {
  const std::string doc = test::read_file(test::source_path("docs/fdi.md"));
  const auto start = doc.find("\n## Configuration");
  ASSERT_NE(start, std::string::npos);
  const auto end = doc.find("\n## ", start + 1);
  const std::string section = doc.substr(start, end == std::string::npos ? std::string::npos : end - start);
  // The keys' table; the constants under their own heading point to their page.
  const auto constants = section.find("\n### Fixed design constants");
  ASSERT_NE(constants, std::string::npos);
  const std::regex row(R"(^\| `([A-Za-z0-9_]+)` \|)");
  expect_same_keys(names_matching(section.substr(0, constants), row), "docs/fdi.md \"Configuration\"");
  EXPECT_NE(section.find("fdi_design_constants.md", constants), std::string::npos);
  EXPECT_NE(section.find("tetra replay --config-keys"), std::string::npos);
}

TEST(ConfigKeys, TheConstantsPageNamesEveryConstantWithItsValue) {
  const std::string page = test::read_file(test::source_path("docs/fdi_design_constants.md"));
  const std::regex row(R"(^\| `([A-Za-z0-9_]+)` \| [^|]+ \| ([^ |]+) \|)");
  expect_same_names(names_matching(page, row), constant_names(), "docs/fdi_design_constants.md");
  std::istringstream in(page);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (!std::regex_search(line, m, row)) continue;
    for (const auto& constant : design_constants()) {
      if (m[1].str() == constant.name) {
        EXPECT_EQ(std::stod(m[2].str()), constant.value) << line;
      }
    }
  }
}

// Sets the key to v.
void set(PipelineConfig& c, const ConfigKey& key, double v) {
  if (const auto* d = std::get_if<double PipelineConfig::*>(&key.field)) c.*(*d) = v;
  if (const auto* o = std::get_if<std::optional<double> PipelineConfig::*>(&key.field)) c.*(*o) = v;
}

bool numeric(const ConfigKey& key) {
  return !std::holds_alternative<bool PipelineConfig::*>(key.field) &&
         !std::holds_alternative<Quaternion PipelineConfig::*>(key.field);
}

// The value just beyond a limit (outward is -1 at the minimum, +1 at the maximum), and just within it.
double just_outside(const ConfigLimit& limit, double outward) {
  if (limit.edge == Edge::kOpen) return limit.value;
  return std::nextafter(limit.value, outward * std::numeric_limits<double>::infinity());
}
double just_inside(const ConfigLimit& limit, double outward) {
  if (limit.edge == Edge::kClosed) return limit.value;
  return std::nextafter(limit.value, -outward * std::numeric_limits<double>::infinity());
}

TEST(ConfigKeys, EveryRangeRefusesAValueJustOutsideItNamingTheKey) {
  int limits = 0;
  for (const auto& key : config_keys()) {
    if (!numeric(key)) continue;
    for (const auto& [limit, outward] : {std::pair{key.min, -1.0}, std::pair{key.max, 1.0}}) {
      if (limit.edge == Edge::kNone) continue;
      ++limits;
      PipelineConfig c;
      set(c, key, just_inside(limit, outward));
      EXPECT_TRUE(validate(c).ok()) << key.name << " refuses " << just_inside(limit, outward);
      const double bad = just_outside(limit, outward);
      set(c, key, bad);
      const Status st = validate(c);
      ASSERT_FALSE(st.ok()) << key.name << " accepts " << bad;
      const std::string& message = st.error().message;
      EXPECT_NE(message.find(std::string("pipeline.") + key.name + ": must be " + range_text(key)),
                std::string::npos)
          << message;
      EXPECT_NE(message.find(", got "), std::string::npos) << message;

      // The same through a file: the source and the key (a denormal is refused as a number already).
      std::ostringstream yaml;
      yaml.precision(17);
      yaml << "pipeline:\n  " << key.name << ": " << bad << "\n";
      const auto parsed = parse_pipeline_config(yaml.str(), "cfg.yaml");
      ASSERT_FALSE(parsed.ok()) << yaml.str();
      EXPECT_NE(parsed.error().message.find("cfg.yaml"), std::string::npos) << parsed.error().message;
      EXPECT_NE(parsed.error().message.find(std::string("pipeline.") + key.name + ": "), std::string::npos)
          << parsed.error().message;
    }
    PipelineConfig c;  // every number must be finite
    set(c, key, std::numeric_limits<double>::quiet_NaN());
    EXPECT_FALSE(validate(c).ok()) << key.name;
  }
  EXPECT_GE(limits, 31);  // every number has at least a lower limit, some an upper one too
}

TEST(ConfigKeys, EveryNumberHasALimitAndEveryKeyADescription) {
  for (const auto& key : config_keys()) {
    EXPECT_GT(std::string(key.description).size(), 10U) << key.name;
    EXPECT_FALSE(std::string(key.unit).empty()) << key.name;
    if (numeric(key)) {
      EXPECT_NE(key.min.edge, Edge::kNone) << key.name;
    }
  }
  for (const auto& constant : design_constants()) {
    EXPECT_GT(std::string(constant.description).size(), 10U) << constant.name;
    EXPECT_FALSE(std::string(constant.unit).empty()) << constant.name;
    EXPECT_TRUE(std::isfinite(constant.value)) << constant.name;
    EXPECT_EQ(table_names().count(constant.name), 0U) << constant.name << " is a key and a constant";
  }
}

TEST(ConfigKeys, AtMostThirtyKeys) {
  // Issue 37's target: the `pipeline:` map at 30 keys or fewer (latitude_deg and initial_q_wxyz counted);
  // what a user has no physical reason to set is a fixed design constant.
  EXPECT_LE(config_keys().size(), 30U);
  EXPECT_EQ(config_keys().size(), 29U);
  EXPECT_EQ(design_constants().size(), 69U);
}

// Issue 37's rule: no decision constant outside the one table. Every named constant the library's sources
// declare is either a row of design_constants() (namespace design) or one of these, which decide nothing: a
// number of mathematics, a numerical method's step, a store's size, a code or an index.
TEST(ConfigKeys, NoDecisionConstantOutsideTheTable) {
  const std::map<std::string, std::string> not_decisions = {
      {"kNaN", "a value"},
      {"kInf", "a value"},
      {"kNotAProbability", "a value"},
      {"kMedianOfHalfNormal", "mathematics: median of |N(0,1)|"},
      {"kNoiseExpectedMedian", "mathematics: median of |N(0,1)|"},
      {"kWhiteD4", "mathematics: C(8,4)"},
      {"kQuantizationD4", "mathematics: C(10,5)"},
      {"kEven", "mathematics: the fourth difference's weights"},
      {"kSiegmundOvershoot", "mathematics: Siegmund's overshoot"},
      {"kVectorOvershoot", "mathematics: Crosier's overshoot"},
      {"kBiasWanderPerB", "mathematics: a Gauss-Markov sigma per bias instability"},
      {"kArlSteps", "numerics: quadrature steps"},
      {"kBiasNodes", "numerics: quadrature nodes"},
      {"kSearchSteps", "numerics: golden-section steps"},
      {"kRankTolerance", "numerics: rank"},
      {"kRatioMargin", "numerics: rounding"},
      {"kMaxSpan_s", "numerics: overflow guard"},
      {"kMax", "numerics: overflow guard"},
      {"kBins", "store"},
      {"kCopies", "store"},
      {"kSpacing_ns", "store"},
      {"kCapacity", "store"},
      {"kSpikeMemory", "store"},
      {"kHistory", "store"},
      {"kSnapshots", "store"},
      {"kCachedGyros", "store"},
      {"kMaxUnitGyros", "store: a mask's bits"},
      {"kColumn", "a matrix's size"},
      {"kPerGyro", "a matrix's size"},
      {"kWidth", "text width"},
      {"kFree", "a range without an edge"},
      {"kBudgetTestCount", "a count of the budget's rows"},
      {"kEvidenceSourceCount", "a count of sources"},
      {"kLargestShare", "the budget table's largest share"},
      {"kReference", "an index"},
      {"kDrift", "an index"},
      {"kCalibration", "an index"},
      {"kNoise", "an index"},
      {"kHypothesisNone", "a code"},
      {"kHypothesisNoise", "a code"},
      {"kHypothesisCalibration", "a code"},
      {"kHypothesisDrift", "a code"},
      {"kHypothesisReference", "a code"},
      {"kKeys", "the keys' table"},
      {"kConstants", "this table"}};
  // Every named constant, whatever its name; the table's own (namespace design) are its rows.
  const std::regex declaration(
      R"(constexpr\s+(?:static\s+)?(?:const\s+)?[A-Za-z_:<>0-9, ]+\s+([A-Za-z_][A-Za-z0-9_]*)\s*[=\[{])");
  const std::set<std::string> rows = constant_names();
  int files = 0;
  for (const char* folder : {"fdi/src", "fdi/include/tetra/fdi"}) {
    for (const auto& entry : std::filesystem::directory_iterator(test::source_path(folder))) {
      const std::string text = test::read_file(entry.path().string());
      ++files;
      for (auto it = std::sregex_iterator(text.begin(), text.end(), declaration);
           it != std::sregex_iterator(); ++it) {
        const std::string name = (*it)[1].str();
        EXPECT_TRUE(not_decisions.count(name) == 1 || rows.count(name) == 1)
            << entry.path().filename().string() << " declares " << name
            << ": a decision constant belongs in namespace design and design_constants(), one row";
      }
    }
  }
  EXPECT_GT(files, 40);
}

TEST(ConfigKeys, AFileThatSetsADesignConstantIsRefusedNamingIt) {
  for (const auto& constant : design_constants()) {
    std::ostringstream yaml;
    yaml.precision(17);
    yaml << "pipeline:\n  max_gap_s: 2\n  " << constant.name << ": " << constant.value << "\n";
    const auto parsed = parse_pipeline_config(yaml.str(), "cfg.yaml");
    ASSERT_FALSE(parsed.ok()) << yaml.str();
    const std::string& message = parsed.error().message;
    EXPECT_NE(
        message.find(std::string("cfg.yaml:3: pipeline.") + constant.name + ": a fixed design constant"),
        std::string::npos)
        << message;
  }
  // A name neither a key nor a constant: unknown, the message listing the keys alone.
  const auto unknown = parse_pipeline_config("pipeline:\n  noise_windw: 30\n", "cfg.yaml");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("cfg.yaml:2: pipeline: unknown key 'noise_windw'"),
            std::string::npos)
      << unknown.error().message;
  EXPECT_EQ(unknown.error().message.find("noise_window"), std::string::npos) << unknown.error().message;
}

TEST(ConfigKeys, TheInitialQuaternionMustBeAUnitOne) {
  const auto parsed = parse_pipeline_config("pipeline:\n  initial_q_wxyz: [1, 0.1, 0, 0]\n", "cfg.yaml");
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.error().message.find("pipeline.initial_q_wxyz: must be a unit quaternion"),
            std::string::npos);
}

TEST(ConfigKeys, TheListingShowsEveryKeysUnitRangeAndDefault) {
  const std::string listing = describe_keys();
  const PipelineConfig defaults;
  std::istringstream in(listing);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("key ", 0), 0U) << line;
  for (const auto& key : config_keys()) {
    ASSERT_TRUE(std::getline(in, line)) << key.name;
    std::istringstream row(line);
    std::string name, unit;
    row >> name >> unit;
    EXPECT_EQ(name, key.name);
    EXPECT_EQ(unit, key.unit);
    EXPECT_NE(line.find("  " + range_text(key) + "  "), std::string::npos) << line;
    EXPECT_NE(line.find("  " + value_text(defaults, key) + "  "), std::string::npos) << line;
    EXPECT_NE(line.find(key.description), std::string::npos) << line;
  }
  // The constants under their own heading: name, unit, value, meaning.
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_TRUE(line.empty()) << line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line.rfind("fixed design constants", 0), 0U) << line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line.rfind("constant ", 0), 0U) << line;
  for (const auto& constant : design_constants()) {
    ASSERT_TRUE(std::getline(in, line)) << constant.name;
    std::istringstream row(line);
    std::string name, unit;
    double value = 0.0;
    row >> name >> unit >> value;
    EXPECT_EQ(name, constant.name);
    EXPECT_EQ(unit, constant.unit);
    EXPECT_EQ(value, constant.value) << line;
    EXPECT_NE(line.find(constant.description), std::string::npos) << line;
  }
  EXPECT_FALSE(std::getline(in, line));

  const auto run = test::run_tetra("replay --config-keys");
  EXPECT_EQ(run.exit_status, 0) << run.err;
  EXPECT_EQ(run.out, listing);
  const auto example = test::run_tetra("replay --config-example");
  EXPECT_EQ(example.exit_status, 0) << example.err;
  EXPECT_EQ(example.out, example_config());
}

}  // namespace
}  // namespace tetra::fdi
