// TDMS logs (docs/formats.md, "TDMS"): files written by tests/tdms/make_tdms.py (Python's struct module,
// following NI's published format description: an independent route) read by every command that reads a
// log, with the same results as the CSV they came from; hostile files built byte by byte here end in one
// error line naming the file and the segment, never a crash or a huge allocation.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/tdms.hpp"

namespace tetra {
namespace {

using test::run_shell;
using test::run_tetra;
using test::source_path;
using test::TempDir;

// make_tdms.py IN OUT ARGS; true when it worked.
void make_tdms(const std::string& in, const std::string& out, const std::string& args = "") {
  const auto r =
      run_shell("python3 " + source_path("tests/tdms/make_tdms.py") + " " + in + " " + out + " " + args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
}

// A file's lines without its provenance comments (command, inputs, time).
std::string without_comments(const std::string& text) {
  std::string out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    if (text[pos] != '#') out += text.substr(pos, end - pos + 1);
    pos = end + 1;
  }
  return out;
}

// The acceptance case: the seed's 16-position plan (examples/turntable.csv) recorded as TDMS, in both
// layouts and byte orders, calibrates to exactly the CSV's calibration (double values copied bit for bit).
TEST(TdmsLog, SixteenPositionPlanCalibratesAsItsCsv) {
  TempDir dir;
  const std::string csv = source_path("examples/turntable.csv");
  make_tdms(csv, dir.file("plan.tdms"), "--int32 sequence --index");
  make_tdms(csv, dir.file("plan_il.tdms"), "--layout interleaved --big-endian --int32 sequence");
  const auto ref = run_tetra("calibrate " + csv + " -o " + dir.file("csv.yaml"));
  ASSERT_EQ(ref.exit_status, 0) << ref.err;
  for (const char* name : {"plan", "plan_il"}) {
    const auto r = run_tetra("calibrate " + dir.file(std::string(name) + ".tdms") + " -o " +
                             dir.file(std::string(name) + ".yaml"));
    ASSERT_EQ(r.exit_status, 0) << r.err;
    EXPECT_EQ(without_comments(test::read_file(dir.file("csv.yaml"))),
              without_comments(test::read_file(dir.file(std::string(name) + ".yaml"))))
        << name;
  }
}

// A faulted gyro log with other channel names, mapped by the map beside it: replay gives the CSV's attitude
// and events, allan the same report, convert the same rows.
TEST(TdmsLog, GyroLogWithChannelMapReplaysAsItsCsv) {
  TempDir dir;
  const std::string csv = dir.file("log.csv");
  auto r =
      run_tetra("sim static --minutes 0.5 --rate-hz 20 --fault gyro=2,kind=bias,at=10,size=0.5 -o " + csv);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  make_tdms(
      csv, dir.file("lab.tdms"),
      "--rename time_s=Time g1=FOG_A g2=FOG_B g3=FOG_C g4=FOG_D --rename-property latitude_deg=Latitude");
  test::write_file(dir.file("lab.channels.yaml"),
                   "channels:\n  time_s: Time\n  g1: FOG_A\n  g2: Log/FOG_B\n  g3: FOG_C\n  g4: FOG_D\n"
                   "properties:\n  latitude_deg: Latitude\n");
  const std::string cal = "--calibration " + source_path("examples/factory.yaml");
  for (const char* in : {"log.csv", "lab.tdms"}) {
    const std::string base = dir.file(in);
    r = run_tetra("replay " + base + " " + cal + " --latitude -23.2 --attitude " + base +
                  ".att.csv --events " + base + ".ev.jsonl");
    ASSERT_EQ(r.exit_status, 0) << r.err;
    r = run_tetra("convert " + base + " " + base + ".out.csv");
    ASSERT_EQ(r.exit_status, 0) << r.err;
  }
  const auto att = test::read_file(dir.file("log.csv.att.csv"));
  EXPECT_EQ(without_comments(att), without_comments(test::read_file(dir.file("lab.tdms.att.csv"))));
  EXPECT_EQ(test::read_file(dir.file("log.csv.ev.jsonl")), test::read_file(dir.file("lab.tdms.ev.jsonl")));
  EXPECT_NE(test::read_file(dir.file("log.csv.ev.jsonl")).find("isolat"), std::string::npos);
  EXPECT_EQ(without_comments(test::read_file(dir.file("log.csv.out.csv"))),
            without_comments(test::read_file(dir.file("lab.tdms.out.csv"))));
  // The file property renamed by the map is the CSV's comment.
  auto log = read_gyro_log(dir.file("lab.tdms"));
  ASSERT_TRUE(log) << log.error().message;
  EXPECT_TRUE(log->meta("latitude_deg").has_value());
}

// ---- byte-level files -------------------------------------------------------------------------------

struct Bytes {
  std::vector<std::uint8_t> b;
  void raw(const void* p, std::size_t n) {
    const auto* c = static_cast<const std::uint8_t*>(p);
    b.insert(b.end(), c, c + n);
  }
  void u32(std::uint32_t v) { raw(&v, 4); }
  void u64(std::uint64_t v) { raw(&v, 8); }
  void f64(double v) { raw(&v, 8); }
  void text(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
};

// One little-endian segment: lead-in, metadata, raw data.
Bytes segment(std::uint32_t toc, const Bytes& meta, const Bytes& raw) {
  Bytes s;
  s.raw("TDSm", 4);
  s.u32(toc);
  s.u32(4713);
  s.u64(meta.b.size() + raw.b.size());
  s.u64(meta.b.size());
  s.raw(meta.b.data(), meta.b.size());
  s.raw(raw.b.data(), raw.b.size());
  return s;
}

// Metadata of channels "/'g'/'a'" and "/'g'/'b'" of `count` doubles each, with a file property.
Bytes two_channels(std::uint64_t count) {
  Bytes m;
  m.u32(3);
  m.text("/");
  m.u32(0xFFFFFFFF);
  m.u32(1);
  m.text("units");
  m.u32(0x20);
  m.text("dps");
  for (const char* path : {"/'g'/'a'", "/'g'/'b'"}) {
    m.text(path);
    m.u32(20);
    m.u32(10);
    m.u32(1);
    m.u64(count);
    m.u32(0);
  }
  return m;
}

Bytes doubles(std::initializer_list<double> v) {
  Bytes r;
  for (double x : v) r.f64(x);
  return r;
}

Result<TdmsFile> parse(const Bytes& file) {
  return parse_tdms(file.b, "x.tdms");
}

TEST(TdmsParse, IncrementalMetadataAndInterleavedChunks) {
  Bytes file = segment(0x0E, two_channels(2), doubles({1, 2, 10, 20}));  // contiguous: a a b b
  Bytes seg2 = segment(0x08, {}, doubles({3, 4, 30, 40}));  // previous metadata, contiguous: one chunk
  file.raw(seg2.b.data(), seg2.b.size());
  Bytes m3;  // incremental: "b" as before, "a" with one value per chunk; interleaved
  m3.u32(1);
  m3.text("/'g'/'a'");
  m3.u32(20);
  m3.u32(10);
  m3.u32(1);
  m3.u64(1);
  m3.u32(0);
  Bytes seg3 =
      segment(0x0A | 0x20, m3, doubles({5, 50, 6, 60, 7, 70}));  // a has 1, b 2 values a chunk: refused
  Bytes bad = file;
  bad.raw(seg3.b.data(), seg3.b.size());
  const auto refused = parse(bad);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("x.tdms: segment 3 at byte"), std::string::npos)
      << refused.error().message;
  EXPECT_NE(refused.error().message.find("different value counts"), std::string::npos);
  m3.b.clear();
  m3.u32(2);
  for (const char* path : {"/'g'/'a'", "/'g'/'b'"}) {
    m3.text(path);
    m3.u32(20);
    m3.u32(10);
    m3.u32(1);
    m3.u64(1);
    m3.u32(0);
  }
  seg3 = segment(0x0A | 0x20, m3, doubles({5, 50, 6, 60}));  // two interleaved chunks of one row each
  file.raw(seg3.b.data(), seg3.b.size());
  const auto ok = parse(file);
  ASSERT_TRUE(ok) << ok.error().message;
  ASSERT_EQ(ok->channels.size(), 2U);
  EXPECT_EQ(ok->channels[0].values, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(ok->channels[1].values, (std::vector<double>{10, 20, 30, 40, 50, 60}));
  ASSERT_EQ(ok->properties.size(), 1U);
  EXPECT_EQ(ok->properties[0].second, "dps");
}

// Each hostile file: a one-line error naming the file and the segment; nothing allocated beyond the file.
TEST(TdmsParse, HostileFilesNameFileAndSegment) {
  struct Case {
    const char* what;
    Bytes file;
    const char* expect;
  };
  std::vector<Case> cases;
  const Bytes good = segment(0x0E, two_channels(2), doubles({1, 2, 10, 20}));
  {
    Bytes f = good;
    f.b.resize(f.b.size() - 3);
    cases.push_back({"truncated raw data", f, "runs past the end of the file"});
  }
  {
    Bytes f = good;
    f.b.resize(20);
    cases.push_back({"truncated lead-in", f, "truncated lead-in"});
  }
  {
    Bytes f = good;
    const std::uint64_t huge = 1ULL << 62;
    std::memcpy(f.b.data() + 12, &huge, 8);
    cases.push_back({"absurd next offset", f, "runs past the end"});
  }
  {
    Bytes f = good;
    const std::uint64_t beyond = f.b.size();
    std::memcpy(f.b.data() + 20, &beyond, 8);
    cases.push_back({"raw offset beyond the segment", f, "raw data offset"});
  }
  {
    Bytes f = segment(0x0E, two_channels(1ULL << 60), doubles({1, 2}));
    cases.push_back({"absurd value count", f, "cannot fit in the file"});
  }
  {
    Bytes f = segment(0x0E, two_channels(3), doubles({1, 2, 10, 20}));
    cases.push_back({"raw data not whole chunks", f, "not a whole number of chunks"});
  }
  {
    Bytes f = good;
    std::memcpy(f.b.data(), "TDSh", 4);
    cases.push_back({"index file", f, ".tdms_index"});
  }
  {
    Bytes f = good;
    f.b[0] = 'X';
    cases.push_back({"bad tag", f, "no 'TDSm' tag"});
  }
  {
    Bytes m;
    m.u32(1);
    m.text("/'g'/'a'");
    m.u32(0);  // "same index as before" in the first segment
    m.u32(0);
    cases.push_back({"index reused before it exists", segment(0x0E, m, {}), "never had"});
  }
  {
    Bytes m;
    m.u32(0xFFFFFFFF);  // four billion objects in a few bytes
    cases.push_back({"absurd object count", segment(0x0E, m, {}), "truncated object entry"});
  }
  for (const auto& c : cases) {
    const auto r = parse(c.file);
    ASSERT_FALSE(r) << c.what;
    const std::string& m = r.error().message;
    EXPECT_EQ(m.find('\n'), std::string::npos) << c.what;
    EXPECT_EQ(m.rfind("x.tdms: segment 1 at byte 0: ", 0), 0U) << c.what << ": " << m;
    EXPECT_NE(m.find(c.expect), std::string::npos) << c.what << ": " << m;
  }
}

TEST(TdmsParse, TableNeedsNumericColumnsOfEqualLength) {
  Bytes m = two_channels(2);
  Bytes f = segment(0x0E, m, doubles({1, 2, 10, 20}));
  Bytes m2;  // "a" has no data in this segment, "b" one more value
  m2.u32(2);
  m2.text("/'g'/'a'");
  m2.u32(0xFFFFFFFF);
  m2.u32(0);
  m2.text("/'g'/'b'");
  m2.u32(20);
  m2.u32(10);
  m2.u32(1);
  m2.u64(1);
  m2.u32(0);
  Bytes s2 = segment(0x0A, m2, doubles({30}));
  f.raw(s2.b.data(), s2.b.size());
  const auto file = parse(f);
  ASSERT_TRUE(file) << file.error().message;
  const auto table = tdms_to_table(*file, {});
  ASSERT_FALSE(table);
  EXPECT_NE(table.error().message.find("channel 'b' has 3 values, channel 'a' has 2"), std::string::npos)
      << table.error().message;
  TdmsChannelMap map;
  map.source = "m.yaml";
  map.channels = {{"time_s", "nope"}};
  const auto unmapped = tdms_to_table(*file, map);
  ASSERT_FALSE(unmapped);
  EXPECT_NE(
      unmapped.error().message.find("m.yaml: channels: no channel 'nope' in x.tdms (channels: g/a, g/b)"),
      std::string::npos)
      << unmapped.error().message;
}

TEST(TdmsLog, CommandLineErrorsAreOneLineExitTwo) {
  TempDir dir;
  test::write_file(dir.file("bad.tdms"), "TDSm\x0e");
  const auto r = run_tetra("allan " + dir.file("bad.tdms"));
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find("bad.tdms: segment 1 at byte 0: truncated lead-in"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace tetra
