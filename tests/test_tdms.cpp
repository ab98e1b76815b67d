// TDMS logs (docs/formats.md, "TDMS"): files written by tests/tdms/make_tdms.py (Python's struct module,
// following NI's published format description: an independent route) read by every command that reads a
// log, with the same results as the CSV they came from; hostile files built byte by byte here end in one
// error line naming the file and the segment, never a crash or a huge allocation.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/core/csv.hpp"
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
    if (n == 0) return;
    const std::size_t at = b.size();
    b.resize(at + n);
    std::memcpy(&b[at], p, n);
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

// ---- memory: the table's cells, never the file or a copy of its values ---------------------------------

// Peak resident memory [kB] of `tetra ARGS` (getrusage of the child, through Python), or -1.
long peak_rss_kb(const std::string& args) {
  const auto r = run_shell(
      "python3 -c 'import resource, subprocess, sys; r = subprocess.run(sys.argv[1:]); "
      "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss if r.returncode == 0 else -1)' " +
      std::string(TETRA_BINARY) + " " + args);
  return r.exit_status == 0 ? std::stol(r.out) : -1;
}

// A 20 MB int8 file (2.5 million rows of time and 4 gyros: 100 MB of doubles) converts in its cells' memory
// and a little more (main before: the file, its values and the table, about 2.3 times the cells); as
// 1000-row segments to the same rows; under an address-space limit it cannot fit in, an error naming it.
TEST(TdmsLog, ALargeInt8FileTakesTheMemoryOfItsCells) {
  TempDir dir;
  const std::string one = dir.file("i8.tdms");
  const std::string seg = dir.file("seg.tdms");
  const std::string tool = "python3 " + source_path("tests/tdms/make_int8_tdms.py") + " ";
  ASSERT_EQ(run_shell(tool + one + " 2500000").exit_status, 0);
  ASSERT_EQ(run_shell(tool + seg + " 2500000 --segment-rows 1000").exit_status, 0);
  ASSERT_EQ(run_shell(tool + dir.file("tiny.tdms") + " 1000").exit_status, 0);
  const long base = peak_rss_kb("convert " + dir.file("tiny.tdms") + " /dev/null");
  const long big = peak_rss_kb("convert " + one + " /dev/null");
  ASSERT_GT(base, 0);
  ASSERT_GT(big, 0);
  const long cells_kb = 2500000L * 5 * 8 / 1024;
  EXPECT_LT(big - base, cells_kb * 5 / 4) << "peak " << big << " kB, a tiny file's " << base << " kB";
  auto r = run_tetra("convert " + one + " " + dir.file("one.csv"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  r = run_tetra("convert " + seg + " " + dir.file("seg.csv"));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string rows = without_comments(test::read_file(dir.file("one.csv")));
  EXPECT_EQ(rows, without_comments(test::read_file(dir.file("seg.csv"))));
  EXPECT_EQ(rows.substr(0, 41), "time_s,g1,g2,g3,g4\n0,-100,-100,-100,-100\n");
  r = run_shell("ulimit -v 100000; " + std::string(TETRA_BINARY) + " convert " + one + " /dev/null");
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find(one + ": its 2500000 rows of 5 columns need 100 MB as numbers"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("bad_alloc"), std::string::npos) << r.err;
}

// ---- bounded work: linear in the file -----------------------------------------------------------------

// Channel `path`'s object: a raw data index of `count` values of `type` (or a marker), no properties.
void channel_object(Bytes& m, const std::string& path, std::uint32_t type, std::uint64_t count) {
  m.text(path);
  m.u32(20);
  m.u32(type);
  m.u32(1);
  m.u64(count);
  m.u32(0);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A LabVIEW-style stream, the metadata once and then 12,000 segments of 10 rows (20 minutes at 100 Hz):
// each segment's values were copied again with all before them (4.0 s here, 61.6 s for the hour of
// bench/tdms_segments.sh); read in one pass, 0.07 s. The bounds leave room for a loaded machine.
TEST(TdmsParse, ManySmallSegmentsReadInLinearTime) {
  constexpr int kSegments = 12000;
  Bytes raw;
  for (int k = 0; k < 20; ++k) raw.f64(k);
  Bytes file = segment(0x0E, two_channels(10), raw);
  const Bytes next = segment(0x08, {}, raw);
  for (int s = 1; s < kSegments; ++s) file.raw(next.b.data(), next.b.size());
  const auto t0 = std::chrono::steady_clock::now();
  const auto parsed = parse(file);
  const double elapsed = seconds_since(t0);
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_EQ(parsed->channels[1].values.size(), 10U * kSegments);
  EXPECT_LT(elapsed, 1.0) << "many small segments";
}

// 30,000 channels listed once, then 10,000 segments that each update one channel's property: each
// segment's metadata cost the whole list (copied, and every channel's place reset); 100 updates of an
// object's 4,000 properties cost 4,000 comparisons each (11 s and 8 s; now 0.1 s and 0.2 s).
TEST(TdmsParse, ManyObjectsAndManyUpdatesReadInLinearTime) {
  Bytes m;
  constexpr std::uint32_t kChannels = 30000;
  m.u32(kChannels);
  for (std::uint32_t c = 0; c < kChannels; ++c) {
    m.text("/'g'/'c" + std::to_string(c) + "'");
    m.u32(0xFFFFFFFF);
    m.u32(0);
  }
  Bytes file = segment(0x0E, m, {});
  for (int s = 0; s < 10000; ++s) {
    Bytes u;
    u.u32(1);
    u.text("/'g'/'c" + std::to_string(s % kChannels) + "'");
    u.u32(0xFFFFFFFF);
    u.u32(1);
    u.text("note");
    u.u32(0x20);
    u.text(std::to_string(s));
    const Bytes seg = segment(0x02, u, {});
    file.raw(seg.b.data(), seg.b.size());
  }
  Bytes p;  // one object, 4,000 properties, given again in 200 segments
  p.u32(1);
  p.text("/");
  p.u32(0xFFFFFFFF);
  p.u32(4000);
  for (int k = 0; k < 4000; ++k) {
    p.text("property " + std::to_string(k));
    p.u32(0x20);
    p.text("v");
  }
  const Bytes props = segment(0x02, p, {});
  for (int s = 0; s < 100; ++s) file.raw(props.b.data(), props.b.size());
  const auto t0 = std::chrono::steady_clock::now();
  const auto parsed = parse(file);
  const double elapsed = seconds_since(t0);
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_EQ(parsed->channels.size(), kChannels);
  EXPECT_EQ(parsed->channels[9999].properties.at(0).second, "9999");
  EXPECT_EQ(parsed->properties.size(), 4000U);
  EXPECT_LT(elapsed, 2.0);
}

// 65,536 channels with values and no channel map: refused as more than 1,024 columns at once (every
// name was compared with every other first: seconds).
TEST(TdmsParse, HugeChannelCountsAreRefusedAtOnce) {
  Bytes m;
  constexpr std::uint32_t kChannels = 65536;
  m.u32(kChannels);
  for (std::uint32_t c = 0; c < kChannels; ++c) channel_object(m, "/'g'/'c" + std::to_string(c) + "'", 5, 1);
  Bytes raw;
  raw.b.assign(kChannels, 1);
  const auto t0 = std::chrono::steady_clock::now();
  const auto parsed = parse(segment(0x0E, m, raw));
  ASSERT_TRUE(parsed) << parsed.error().message;
  const auto table = tdms_to_table(*parsed, {});
  const double elapsed = seconds_since(t0);
  ASSERT_FALSE(table);
  EXPECT_EQ(table.error().message, "x.tdms: more than 1024 channels");
  EXPECT_LT(elapsed, 2.0);
}

// A segment whose table of contents says "no raw data" but holds some: refused, not 200 of 600 rows
// dropped without a word.
TEST(TdmsParse, RawBytesTheTableOfContentsDenies) {
  Bytes file = segment(0x0E, two_channels(2), doubles({1, 2, 10, 20}));
  const Bytes denied = segment(0x00, {}, doubles({3, 4, 30, 40}));
  file.raw(denied.b.data(), denied.b.size());
  const auto parsed = parse(file);
  ASSERT_FALSE(parsed);
  EXPECT_EQ(parsed.error().message,
            "x.tdms: segment 2 at byte 169: 32 bytes after the metadata but the table of contents says the "
            "segment has no raw data");
}

// Property names with blanks or '=' stay one key in the comments ("x units=dps" never reads as
// "units=dps"); the map's name for a property wins over a file property of that name, whatever their
// order; one channel is never two columns; a channel map that is a link to nothing is refused by name.
TEST(TdmsParse, PropertyNamesMapsAndChannelsEnterOnce) {
  Bytes m = two_channels(1);
  // two_channels' file object has one property; give it two more: "x units=dps" and "latitude_deg".
  Bytes f;
  f.u32(1);
  f.text("/");
  f.u32(0xFFFFFFFF);
  f.u32(3);
  f.text("x units=dps");
  f.u32(0x20);
  f.text("V");
  f.text("site latitude");
  f.u32(0x20);
  f.text("-23.2");
  f.text("latitude_deg");
  f.u32(0x20);
  f.text("51");
  Bytes file = segment(0x0E, m, doubles({1, 10}));
  const Bytes props = segment(0x02, f, {});
  file.raw(props.b.data(), props.b.size());
  const auto parsed = parse(file);
  ASSERT_TRUE(parsed) << parsed.error().message;
  TdmsChannelMap map;
  map.source = "m.yaml";
  map.channels = {{"time_s", "a"}, {"g1", "b"}};
  map.properties = {{"latitude_deg", "site latitude"}};
  const auto table = tdms_to_table(*parsed, map);
  ASSERT_TRUE(table) << table.error().message;
  Metadata read_back;
  for (const std::string& c : table->comments) parse_metadata_comment(c, read_back);
  EXPECT_EQ(last_meta(read_back, "units").value_or(""), "dps");  // the file's own; "dps=V" before
  EXPECT_EQ(last_meta(read_back, "x units=dps").value_or(""), "V");
  EXPECT_EQ(last_meta(read_back, "latitude_deg").value_or(""), "-23.2");
  EXPECT_EQ(table->meta("latitude_deg").value_or(""), "-23.2");
  map.channels = {{"time_s", "a"}, {"g1", "b"}, {"g2", "g/b"}};
  const auto twice = tdms_to_table(*parsed, map);
  ASSERT_FALSE(twice);
  EXPECT_EQ(twice.error().message, "m.yaml: channels: g2: channel 'g/b' is also column g1");

  TempDir dir;
  test::write_file(dir.file("run.tdms"), std::string(file.b.begin(), file.b.end()));
  std::filesystem::create_symlink(dir.file("gone.yaml"), dir.file("run.channels.yaml"));
  const auto dangling = read_tdms_table(dir.file("run.tdms"));
  ASSERT_FALSE(dangling);
  EXPECT_NE(dangling.error().message.find(dir.file("run.channels.yaml")), std::string::npos)
      << dangling.error().message;
}

// `tetra convert` of a TDMS log whose channel map (run.channels.yaml beside it) is a folder, a FIFO, a
// device or a link to nothing: exit 2 with one line naming the map and what it is; the FIFO is never
// opened (the read blocked until a writer came), the link to nothing never taken for no map.
TEST(ConvertTdms, AChannelMapThatIsNotARegularFileIsRefusedByName) {
  TempDir dir;
  const Bytes file = segment(0x0E, two_channels(2), doubles({0, 1, 10, 20}));
  test::write_file(dir.file("run.tdms"), std::string(file.b.begin(), file.b.end()));
  const std::string map = dir.file("run.channels.yaml");
  const std::string what = map + ": the channel map of " + dir.file("run.tdms") + " is ";
  const auto convert = [&] {
    return run_shell("timeout -s KILL 10 " + std::string(TETRA_BINARY) + " convert " + dir.file("run.tdms") +
                     " " + dir.file("out.csv"));
  };
  const auto refused = [&](const std::string& kind) {
    const auto r = convert();
    EXPECT_EQ(r.exit_status, 2) << kind << ": " << r.err;
    EXPECT_EQ(r.err, "tetra convert: " + what + kind + "\n") << kind;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.csv"))) << kind;
  };
  std::filesystem::create_directory(map);
  refused("a folder, not a regular file");
  std::filesystem::remove(map);
  ASSERT_EQ(run_shell("mkfifo " + map).exit_status, 0);
  refused("a FIFO, not a regular file");
  std::filesystem::remove(map);
  std::filesystem::create_symlink("/dev/null", map);
  refused("a character device, not a regular file");
  std::filesystem::remove(map);
  std::filesystem::create_symlink(dir.file("gone.yaml"), map);
  refused("a symbolic link to no file");
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
