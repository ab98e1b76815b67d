// Unit tests of the ground station's parts without DDS or HTTP: ring buffer, encoders, store
// (decimation, history, stream resume), link states, command requests and acknowledgement matching.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include "test_support.hpp"
#include "tetra/core/units.hpp"
#include "tetra/ground/command_request.hpp"
#include "tetra/ground/command_tracker.hpp"
#include "tetra/ground/encode.hpp"
#include "tetra/ground/http_api.hpp"
#include "tetra/ground/http_parse.hpp"
#include "tetra/ground/link_state.hpp"
#include "tetra/ground/operators.hpp"
#include "tetra/ground/private_file.hpp"
#include "tetra/ground/query_params.hpp"
#include "tetra/ground/record_files.hpp"
#include "tetra/ground/ring_buffer.hpp"
#include "tetra/ground/store.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

constexpr std::int64_t kUtc0_ns = 1'790'000'000'000'000'000;  // 2026-09-21, an arbitrary UTC

dds::HealthView health(const std::string& unit, GyroMask used, int n = 4) {
  dds::HealthView h;
  h.unit = unit;
  h.health.gyros.resize(static_cast<std::size_t>(n));
  h.health.used = used;
  h.health.chi2 = 1.5;
  h.health.chi2_threshold = 10.8;
  h.health.cusum = 2.0;
  h.health.cusum_threshold = 8.0;
  h.health.parity_residual = 0.7;
  h.health_period_s = 0.5;
  return h;
}

TEST(RingBuffer, KeepsTheNewestItemsAndCountsWhatItDrops) {
  RingBuffer<int> ring(3);
  for (int i = 1; i <= 5; ++i) ring.push(i);
  ASSERT_EQ(ring.size(), 3U);
  EXPECT_EQ(ring[0], 3);
  EXPECT_EQ(ring[2], 5);
  EXPECT_EQ(ring.newest(), 5);
  EXPECT_EQ(ring.dropped(), 2U);
  EXPECT_EQ(ring.partition_point([](int v) { return v < 4; }), 1U);
  EXPECT_EQ(ring.partition_point([](int v) { return v < 100; }), 3U);
}

TEST(Encode, EulerAnglesOfKnownRotations) {
  // 30° about Z: yaw 30, roll and pitch 0; 20° about X: roll 20. Exact to rounding (1e-9 deg).
  const Quaternion yaw(Eigen::AngleAxisd(30 * kDegToRad, Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR(euler_zyx_deg(yaw).yaw_deg, 30.0, 1e-9);
  EXPECT_NEAR(euler_zyx_deg(yaw).roll_deg, 0.0, 1e-9);
  const Quaternion roll(Eigen::AngleAxisd(20 * kDegToRad, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(euler_zyx_deg(roll).roll_deg, 20.0, 1e-9);
  EXPECT_NEAR(euler_zyx_deg(roll).pitch_deg, 0.0, 1e-9);
}

TEST(Encode, ParityFieldsAreNotAvailableWithFewerThanFourGyros) {
  const json four = health_json(health("u", 0b1111), kUtc0_ns);
  EXPECT_TRUE(four["parity_available"].get<bool>());
  EXPECT_DOUBLE_EQ(four["chi2"].get<double>(), 1.5);
  const json three = health_json(health("u", 0b0111), kUtc0_ns);
  EXPECT_FALSE(three["parity_available"].get<bool>());
  EXPECT_TRUE(three["chi2"].is_null());
  EXPECT_TRUE(three["cusum"].is_null());
  EXPECT_TRUE(three["parity_residual"].is_null());
  EXPECT_EQ(three["gyros_used"], json::array({1, 2, 3}));
  EXPECT_DOUBLE_EQ(three["utc_ms"].get<double>(), 1'790'000'000'000.0);  // ns -> ms
  // Fault detection availability is the pipeline's flag, carried as is (health and attitude).
  EXPECT_TRUE(four["fdi_available"].get<bool>());
  auto exhausted = health("u", 0b0111);
  exhausted.health.fdi_available = false;
  EXPECT_FALSE(health_json(exhausted, kUtc0_ns)["fdi_available"].get<bool>());
  fdi::AttitudeEstimate a;
  a.fdi_available = false;
  EXPECT_FALSE(attitude_json("u", a, kUtc0_ns)["fdi_available"].get<bool>());
}

// A unit is named in the API by the hexadecimal of its bytes: every name, UTF-8 or not, has an id of its
// own that gives it back, and the id is the one spelling of it (lowercase, two digits a byte).
TEST(UnitId, EveryNameHasAnIdThatGivesItBack) {
  EXPECT_EQ(unit_id("unit one"), "756e6974206f6e65");
  EXPECT_EQ(unit_id("caf\xe9"), "636166e9");
  std::string every_byte;
  for (int b = 1; b < 256; ++b) every_byte += static_cast<char>(b);
  EXPECT_EQ(unit_of_id(unit_id(every_byte)), every_byte);
  for (const char* bad : {"", "7", "636166E9", "63 6166", "6g", "%e9"})
    EXPECT_FALSE(unit_of_id(bad).has_value()) << bad;
  using Name = std::optional<std::string>;
  EXPECT_EQ(*requested_unit(Name("unit one"), std::nullopt, "parameter"), "unit one");
  EXPECT_EQ(*requested_unit(std::nullopt, Name("636166e9"), "parameter"), "caf\xe9");
  EXPECT_EQ(requested_unit(Name("a"), Name("61"), "parameter").error().message,
            "parameter 'unit' or 'unit_id', not both");
  EXPECT_EQ(requested_unit(std::nullopt, std::nullopt, "parameter").error().message,
            "parameter 'unit' (or 'unit_id') missing");
  EXPECT_EQ(requested_unit(std::nullopt, Name("636166E9"), "parameter").error().message,
            "parameter 'unit_id': the lowercase hexadecimal of the unit's name, as /api/units gives it");
  // Every object the ground shows a unit in carries its id.
  const std::string latin = "caf\xe9";
  EXPECT_EQ(health_json(health(latin, 0b1111), kUtc0_ns)["unit_id"], "636166e9");
  EXPECT_EQ(attitude_json(latin, fdi::AttitudeEstimate{}, kUtc0_ns)["unit_id"], "636166e9");
  dds::EventView event;
  event.unit = latin;
  EXPECT_EQ(event_json(event, 4, kUtc0_ns)["unit_id"], "636166e9");
  GroundStore store(StoreConfig{});
  store.add_health(health(latin, 0b1111), kUtc0_ns, 0);
  EXPECT_EQ(store.units_json(0)[0]["unit_id"], "636166e9");
  AuditRecord record;
  record.unit = latin;
  EXPECT_EQ(json::parse(AuditLog::json_line(record, 0))["unit_id"], "636166e9");
}

TEST(Encode, AcknowledgementCarriesTheAuditTrail) {
  dds::EventView ack;
  ack.unit = "u";
  ack.event_seq = 7;
  ack.command_id = 0xFFFF'FFFF'FFFF'FFF0ULL;  // beyond 2^53: must survive as text
  ack.event.type = fdi::EventType::kCommand;
  ack.event.gyro = 2;
  ack.event.outcome = fdi::CommandOutcome::kRefusedUnobservable;
  ack.event.detail = "exclude 2: refused";
  ack.command = {tetra_COMMAND_EXCLUDE, false, "alice", "ground@127.0.0.1"};
  const json j = ack_json(ack, 4);
  EXPECT_FALSE(j["accepted"].get<bool>());
  EXPECT_EQ(j["command"], "exclude");
  EXPECT_EQ(j["operator"], "alice");
  EXPECT_EQ(j["origin"], "ground@127.0.0.1");
  EXPECT_EQ(j["command_id"], "18446744073709551600");
}

TEST(LinkState, StaleAfterThreeHealthPeriodsServiceLostWithoutWriter) {
  EXPECT_EQ(link_state(std::nullopt, 0.5, true), Link::kWaiting);
  EXPECT_EQ(link_state(1'400'000'000, 0.5, true), Link::kLive);   // 1.4 s < 3 × 0.5 s
  EXPECT_EQ(link_state(1'600'000'000, 0.5, true), Link::kStale);  // 1.6 s > 1.5 s
  EXPECT_EQ(link_state(100'000'000, 0.5, false), Link::kServiceLost);
  EXPECT_STREQ(to_string(Link::kServiceLost), "SERVICE LOST");
}

TEST(Store, AttitudeIsDecimatedToTheStatedRate) {
  StoreConfig config;
  config.history_s = 60;
  config.attitude_rate_hz = 10;
  GroundStore store(config);
  fdi::AttitudeEstimate a;
  // 100 Hz for 2 s of sensor time: 20 kept at 10 Hz (every 10th sample).
  for (int k = 0; k < 200; ++k) {
    a.stamp_ns = std::int64_t{10'000'000} * k;
    store.add_attitude("u", a, kUtc0_ns + a.stamp_ns, 0);
  }
  auto h = store.history("u", "attitude", 0, 1e300, 0);
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(h->size(), 20U);
}

TEST(Store, HistoryIsBoundedAndSelectsTheTimeRange) {
  StoreConfig config;
  config.history_s = 10;
  config.health_rate_hz = 2;  // capacity 20
  GroundStore store(config);
  for (int k = 0; k < 50; ++k)
    store.add_health(health("u", 0b1111), kUtc0_ns + std::int64_t{500'000'000} * k, 0);
  auto all = store.history("u", "health", 0, 1e300, 0);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->size(), 20U);  // the newest 20 of 50
  const double t30_ms = utc_ms(kUtc0_ns + std::int64_t{500'000'000} * 30);
  const double t39_ms = utc_ms(kUtc0_ns + std::int64_t{500'000'000} * 39);
  auto some = store.history("u", "health", t30_ms, t39_ms, 0);
  ASSERT_TRUE(some.ok());
  EXPECT_EQ(some->size(), 10U);
  auto thinned = store.history("u", "health", 0, 1e300, 5);
  EXPECT_LE(thinned->size(), 5U);
  EXPECT_FALSE(store.history("nobody", "health", 0, 1, 0).ok());
  EXPECT_FALSE(store.history("u", "bogus", 0, 1, 0).ok());
}

TEST(Store, StreamResumesAfterTheLastIdAndReportsAGap) {
  StoreConfig config;
  config.stream_capacity = 8;
  GroundStore store(config);
  for (int k = 0; k < 5; ++k) store.add_health(health("u", 0b1111), kUtc0_ns + k, 0);
  auto read = store.read_stream(3, 100, 0ms);
  ASSERT_EQ(read.messages.size(), 2U);
  EXPECT_EQ(read.messages[0].id, 4U);
  EXPECT_FALSE(read.gap);
  for (int k = 0; k < 10; ++k) store.add_health(health("u", 0b1111), kUtc0_ns + k, 0);
  read = store.read_stream(3, 100, 0ms);  // ids 4..7 were pushed out of the 8-message ring
  EXPECT_TRUE(read.gap);
  EXPECT_EQ(read.messages.front().id, 8U);
  EXPECT_EQ(read.messages.back().id, 15U);
}

TEST(Store, LinkGoesStaleThenServiceLostAndIsStreamed) {
  GroundStore store(StoreConfig{});
  store.add_health(health("u", 0b1111), kUtc0_ns, 0);
  store.update_links(100'000'000);
  EXPECT_EQ(store.units_json(100'000'000)[0]["state"], "LIVE");
  store.update_links(2'000'000'000);  // 2 s > 3 × 0.5 s
  EXPECT_EQ(store.units_json(2'000'000'000)[0]["state"], "STALE");
  store.set_writer_alive("u", false, 2'100'000'000);
  EXPECT_EQ(store.units_json(2'100'000'000)[0]["state"], "SERVICE LOST");
  auto read = store.read_stream(0, 100, 0ms);
  int links = 0;
  for (const auto& m : read.messages) links += m.event == "link" ? 1 : 0;
  EXPECT_EQ(links, 3);
}

TEST(CommandTracker, MatchesAnAcknowledgementByIdAndUnit) {
  CommandTracker tracker;
  tracker.expect(42, "u");
  dds::EventView other;
  other.unit = "v";
  other.command_id = 42;  // same id, another unit: not ours
  EXPECT_FALSE(tracker.offer(other));
  dds::EventView ack;
  ack.unit = "u";
  ack.command_id = 42;
  std::thread answer([&] {
    std::this_thread::sleep_for(10ms);
    EXPECT_TRUE(tracker.offer(ack));
  });
  auto got = tracker.wait(42, 5s);
  answer.join();
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->command_id, 42U);
  EXPECT_EQ(tracker.pending(), 0U);
  tracker.expect(43, "u");
  EXPECT_FALSE(tracker.wait(43, 1ms).has_value());  // nobody answers: forgotten after the timeout
  EXPECT_EQ(tracker.pending(), 0U);
}

TEST(CommandRequest, ValidatesEveryField) {
  auto ok = parse_command_request(R"({"unit":"u","action":"exclude","gyro":2,"force":true})", "bob",
                                  "ground@127.0.0.1");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->kind, tetra_COMMAND_EXCLUDE);
  EXPECT_TRUE(ok->force);
  tetra_Command wire{};
  ASSERT_TRUE(to_wire(*ok, 9, wire).ok());
  EXPECT_STREQ(wire.operator_id, "bob");
  EXPECT_STREQ(wire.origin, "ground@127.0.0.1");
  // The operator is the signed-in user: a typed one is refused; so are unknown and repeated keys
  // (the last of two "action" keys would otherwise win).
  for (const char* bad :
       {"", "[]", R"({"action":"reset"})", R"({"unit":"u","action":"reset","operator":"x"})",
        R"({"unit":"u","action":"explode"})", R"({"unit":"u","action":"exclude"})",
        R"({"unit":"u","action":"exclude","gyro":99})", R"({"unit":"u","action":"exclude","gyro":"2"})",
        R"({"unit":"u","action":"reset","gyro":1})", R"({"unit":"u","action":"reset","force":"yes"})",
        R"({"unit":"u","action":"reset","action":"exclude","gyro":1})",
        R"({"unit":"u","action":"reset","x":1})"}) {
    EXPECT_FALSE(parse_command_request(bad, "alice", "o").ok()) << bad;
  }
  EXPECT_NE(parse_command_request(R"({"unit":"u","action":"reset","action":"exclude","gyro":1})", "a", "o")
                .error()
                .message.find("'action' given twice"),
            std::string::npos);
  // The unit by its id: any bytes; by its name or its id, not both.
  auto by_id = parse_command_request(R"({"unit_id":"636166e9","action":"reset"})", "bob", "o");
  ASSERT_TRUE(by_id.ok()) << by_id.error().message;
  EXPECT_EQ(by_id->unit, "caf\xe9");
  for (const char* bad :
       {R"({"unit":"u","unit_id":"75","action":"reset"})", R"({"unit_id":"7","action":"reset"})",
        R"({"unit_id":117,"action":"reset"})", R"({"unit":"","action":"reset"})"}) {
    EXPECT_FALSE(parse_command_request(bad, "alice", "o").ok()) << bad;
  }
  const std::string long_operator(40, 'x');
  auto too_long = parse_command_request(R"({"unit":"u","action":"reset"})", long_operator, "o");
  ASSERT_TRUE(too_long.ok());
  EXPECT_FALSE(to_wire(*too_long, 1, wire).ok());
}

TEST(HttpParse, BeastsParserWithTheGroundsChecksAsBytesArrive) {
  using Kind = ParseOutcome::Kind;
  const ParseLimits limits{256, 16};
  const auto parse = [&](const std::string& in) { return parse_request(in, limits); };
  const std::string get = "GET /api/units?unit=a%20b HTTP/1.1\r\nHost: h\r\n\r\n";
  const auto whole = parse(get + "GET /next HTTP/1.1\r\n");  // a pipelined request's start after it
  ASSERT_EQ(whole.kind, Kind::kRequest) << whole.message;
  EXPECT_EQ(whole.consumed, get.size());
  EXPECT_TRUE(whole.keep_alive);
  EXPECT_EQ(whole.request.path, "/api/units");
  EXPECT_EQ(whole.request.params.at(0).second, "a b");
  EXPECT_EQ(whole.request.header("host"), "h");
  // Every prefix is incomplete, an empty line's CR included; the body is waited for.
  for (std::size_t n = 0; n < get.size(); ++n)
    EXPECT_EQ(parse(get.substr(0, n)).kind, Kind::kIncomplete) << n;
  EXPECT_EQ(parse("\r").kind, Kind::kIncomplete);
  EXPECT_EQ(parse("\r\n" + get).kind, Kind::kRequest);
  const std::string post = "POST /p HTTP/1.0\r\nContent-Length: 5\r\n\r\n";
  EXPECT_EQ(parse(post + "abc").kind, Kind::kIncomplete);
  const auto posted = parse(post + "abcdeXYZ");
  ASSERT_EQ(posted.kind, Kind::kRequest);
  EXPECT_EQ(posted.request.body, "abcde");
  EXPECT_EQ(posted.consumed, post.size() + 5);
  EXPECT_FALSE(posted.keep_alive);  // HTTP/1.0
  // Refused, with the status: at once for a bare LF (Beast would wait for CRLF CRLF), before the body
  // for its length.
  for (const auto& [bytes, status] : std::vector<std::pair<std::string, int>>{
           {"GET / HTTP/1.1\nHost: h\n", 400},
           {"GET / HTTP/1.1\r\nX-A: 1\r\n folded\r\n\r\n", 400},
           {"GET / HTTP/1.1\r\nX-A : 1\r\n\r\n", 400},
           {"POST / HTTP/1.1\r\nContent-Length: 5, 5\r\n\r\nhello", 400},
           {"POST / HTTP/1.1\r\nContent-Length: 17\r\n\r\n", 413},
           {"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n", 501},
           {"GET / HTTP/2.0\r\n\r\n", 400},
           {"GET http://h/ HTTP/1.1\r\n\r\n", 400},
           {"GET / HTTP/1.1\r\nCookie: a\r\nCookie: b\r\n\r\n", 400},
           {"GET / HTTP/1.1\r\nX-A: " + std::string(300, 'a') + "\r\n\r\n", 431},
           {"GET / HTTP/1.1\r\nX-A: " + std::string(300, 'a'), 431}}) {  // longer than the limit, unfinished
    const auto r = parse(bytes);
    EXPECT_EQ(r.kind, Kind::kRefused) << bytes;
    EXPECT_EQ(r.status, status) << bytes << ": " << r.message;
  }
}

TEST(RecordFiles, AttitudeFilterColumnsAfterTheElevenAreReadPast) {
  test::TempDir dir;
  test::write_file(dir.file("att.csv"),
                   "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros,sigma_x_deg,sigma_y_deg,"
                   "sigma_z_deg,bias_1_dps,bias_2_dps,bias_3_dps\n"
                   "0.1,1,0,0,0,0,0.06,0,0.001,NOMINAL,123,0.0005,0.0006,0.0007,1e-6,2e-6,3e-6\n");
  auto att = read_record(dir.path().string(), "att.csv", 0.0, 1.0, 0);
  ASSERT_TRUE(att.ok()) << att.error().message;
  ASSERT_EQ(att->size(), 1U);
  EXPECT_EQ((*att)[0]["gyros"], "123");
}

TEST(RecordFiles, AttitudeAndEventFilesAreServedBySensorTime) {
  test::TempDir dir;
  test::write_file(dir.file("att.csv"),
                   "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros\n"
                   "0.1,1,0,0,0,0,0.06,0,0.001,NOMINAL,1234\n"
                   "0.2,1,0,0,0,0,0.06,0,0.001,DEGRADED,134\n");
  test::write_file(dir.file("ev.jsonl"), "{\"time_s\": 0.15, \"event\": \"isolated\", \"gyro\": 2}\n");
  test::write_file(dir.file("log.csv"), "time_s,g1,g2,g3,g4\n0,1,2,3,4\n");  // a gyro log: not listed
  auto list = list_records(dir.path().string());
  ASSERT_TRUE(list.ok()) << list.error().message;
  EXPECT_EQ(list->size(), 2U);
  auto att = read_record(dir.path().string(), "att.csv", 0.15, 1.0, 0);
  ASSERT_TRUE(att.ok()) << att.error().message;
  ASSERT_EQ(att->size(), 1U);
  EXPECT_EQ((*att)[0]["mode"], "DEGRADED");
  auto ev = read_record(dir.path().string(), "ev.jsonl", 0, 1, 0);
  ASSERT_TRUE(ev.ok());
  EXPECT_EQ((*ev)[0]["event"], "isolated");
  EXPECT_FALSE(read_record(dir.path().string(), "../etc/passwd", 0, 1, 0).ok());
  EXPECT_FALSE(read_record(dir.path().string(), "log.csv", 0, 1, 0).ok());
}

TEST(RecordFiles, NoLinkOutOfTheFolderNoNulNoServerPathInErrors) {
  test::TempDir outside;
  test::write_file(outside.file("secret.jsonl"), "{\"time_s\": 1, \"event\": \"secret\"}\n");
  test::TempDir dir;
  std::filesystem::create_symlink(outside.file("secret.jsonl"), dir.file("link.jsonl"));
  test::write_file(dir.file("dup.jsonl"), "{\"time_s\": 1, \"event\": \"a\", \"event\": \"b\"}\n");
  auto list = list_records(dir.path().string());
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(list->dump().find("link"), std::string::npos) << list->dump();
  const auto linked = read_record(dir.path().string(), "link.jsonl", 0, 10, 0);
  ASSERT_FALSE(linked.ok());
  EXPECT_EQ(linked.error().message.find(dir.path().string()), std::string::npos) << linked.error().message;
  EXPECT_FALSE(read_record(dir.path().string(), std::string("dup.jsonl\0.csv", 14), 0, 10, 0).ok());
  const auto dup = read_record(dir.path().string(), "dup.jsonl", 0, 10, 0);
  ASSERT_FALSE(dup.ok());
  EXPECT_EQ(dup.error().message, "dup.jsonl:1: key 'event' given twice");
  const auto missing = read_record(dir.path().string(), "none.csv", 0, 10, 0);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().message.find('/'), std::string::npos) << missing.error().message;
}

TEST(QueryParams, EveryParameterIsValidatedAndNamed) {
  using P = std::vector<std::pair<std::string, std::string>>;
  auto q = QueryParams::of(P{{"max", "-1"}, {"start", "nan"}, {"end", "12.5"}}, {"max", "start", "end"});
  ASSERT_TRUE(q.ok());
  EXPECT_EQ(q->count("max", 5000, 1, 100000).error().message, "parameter 'max': an integer 1..100000");
  EXPECT_EQ(q->number("start", 0).error().message, "parameter 'start': a finite number");
  EXPECT_DOUBLE_EQ(*q->number("end", 0), 12.5);
  EXPECT_EQ(*q->count("absent", 7, 1, 9), 7U);
  EXPECT_FALSE(QueryParams::of(P{{"max", "1"}, {"max", "2"}}, {"max"}).ok());
  EXPECT_EQ(QueryParams::of(P{{"evil", "1"}}, {"max"}).error().message, "parameter 'evil' unknown here");
}

TEST(Operators, AccountsPasswordsSessionsAndRoles) {
  test::TempDir dir;
  const std::string users = dir.file("users");
  auto hash = hash_password("correct horse");
  ASSERT_TRUE(hash.ok());
  EXPECT_EQ(hash->rfind("$argon2id$", 0), 0U);
  ASSERT_TRUE(set_account(users, {"alice", Role::kCommander, *hash}).ok());
  ASSERT_TRUE(set_account(users, {"victor", Role::kViewer, *hash}).ok());
  EXPECT_FALSE(set_account(users, {"bad name", Role::kViewer, *hash}).ok());
  auto accounts = read_accounts(users);
  ASSERT_TRUE(accounts.ok()) << accounts.error().message;
  ASSERT_EQ(accounts->size(), 2U);
  EXPECT_EQ(std::filesystem::status(users).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  auto ops = Operators::open(users, dir.file("key"), dir.file("sessions"), 1000);
  ASSERT_TRUE(ops.ok()) << ops.error().message;
  EXPECT_FALSE(ops->login("alice", "wrong").has_value());
  EXPECT_FALSE(ops->login("nobody", "correct horse").has_value());
  ASSERT_TRUE(ops->login("alice", "correct horse").has_value());
  const std::string token = *ops->issue("alice", 1000, 3600);
  EXPECT_EQ(token.size(), 64U);  // 32 random bytes, nothing of the user inside
  EXPECT_EQ(token.find("alice"), std::string::npos);
  auto s = ops->session(token, 2000);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->user, "alice");
  EXPECT_EQ(s->role, Role::kCommander);
  EXPECT_EQ(s->csrf.size(), 64U);
  EXPECT_FALSE(ops->session(token, 5000).has_value());  // expired
  std::string forged = token;
  forged[0] = forged[0] == 'b' ? 'c' : 'b';  // another id: not in the store
  EXPECT_FALSE(ops->session(forged, 2000).has_value());
  // In the journal of its file: a restarted ground station still knows the session.
  auto again = Operators::open(users, dir.file("key"), dir.file("sessions"), 1500);
  ASSERT_TRUE(again.ok());
  EXPECT_TRUE(again->session(token, 2000).has_value());
  ASSERT_TRUE(again->revoke(token).ok());
  EXPECT_FALSE(again->session(token, 2000).has_value());
  // The other instance sees the sign-out in the journal, and so does every later start.
  EXPECT_FALSE(ops->session(token, 2000).has_value());
  EXPECT_FALSE(Operators::open(users, dir.file("key"), dir.file("sessions"), 1500)->session(token, 2000));
  // A role changed in the file applies to open sessions.
  const std::string second = *ops->issue("alice", 1000, 3600);
  ASSERT_TRUE(set_account(users, {"alice", Role::kViewer, *hash}).ok());
  std::filesystem::last_write_time(users,
                                   std::filesystem::file_time_type::clock::now() + std::chrono::seconds(5));
  EXPECT_EQ(ops->session(second, 2000)->role, Role::kViewer);
  test::write_file(dir.file("broken"), "alice:admin:$argon2id$x\n");
  EXPECT_EQ(read_accounts(dir.file("broken")).error().message,
            dir.file("broken") + ":1: role must be viewer or commander");
}

// A viewer whose name starts with a commander's name and a dot signed in as that commander when the user
// was read from the session token up to its first dot; a dotted name then had no working session at all.
TEST(Operators, ADottedViewerIsItselfAndNeverTheCommanderItsNameStartsWith) {
  test::TempDir dir;
  const std::string users = dir.file("users");
  const std::string hash = *hash_password("correct horse");
  ASSERT_TRUE(set_account(users, {"alice", Role::kCommander, hash}).ok());
  ASSERT_TRUE(set_account(users, {"alice.2000000000", Role::kViewer, hash}).ok());
  ASSERT_TRUE(set_account(users, {"john.smith", Role::kViewer, hash}).ok());
  ASSERT_TRUE(set_account(users, {"a_b-c.D9", Role::kViewer, hash}).ok());
  auto ops = Operators::open(users, dir.file("key"), dir.file("sessions"), 1000);
  ASSERT_TRUE(ops.ok()) << ops.error().message;
  for (const std::string user : {"alice.2000000000", "john.smith", "a_b-c.D9"}) {
    ASSERT_TRUE(ops->login(user, "correct horse").has_value()) << user;
    const auto session = ops->session(*ops->issue(user, 1000, 3600), 2000);
    ASSERT_TRUE(session.has_value()) << user;
    EXPECT_EQ(session->user, user);
    EXPECT_EQ(session->role, Role::kViewer) << user;
  }
}

TEST(Operators, SignOutSticksPastManySignOutsAndAUserHoldsAtMost64Sessions) {
  test::TempDir dir;
  const std::string users = dir.file("users");
  ASSERT_TRUE(set_account(users, {"alice", Role::kCommander, *hash_password("correct horse")}).ok());
  auto ops = Operators::open(users, dir.file("key"), dir.file("sessions"), 1000);
  ASSERT_TRUE(ops.ok());
  const std::string kept = *ops->issue("alice", 1000, 3600);
  const std::string first = *ops->issue("alice", 1000, 3600);
  ASSERT_TRUE(ops->revoke(first).ok());
  // 400 sign-ins and sign-outs (three journal compactions among them): the first sign-out still holds.
  for (int i = 0; i < 400; ++i) ASSERT_TRUE(ops->revoke(*ops->issue("alice", 1000, 3600)).ok());
  EXPECT_FALSE(ops->session(first, 2000).has_value());
  EXPECT_TRUE(ops->session(kept, 2000).has_value());
  // The journal stays bounded: compacted to the live sessions.
  EXPECT_LT(std::filesystem::file_size(dir.file("sessions")), 100000U);
  // 64 sessions per user: the 65th sign-in ends the one nearest to expiry (here `kept`, the oldest).
  std::vector<std::string> open;
  for (int i = 0; i < 64; ++i) open.push_back(*ops->issue("alice", 1001 + i, 3600));
  EXPECT_FALSE(ops->session(kept, 2000).has_value());
  for (const auto& id : open) EXPECT_TRUE(ops->session(id, 2000).has_value());
}

TEST(Operators, AKeyOrJournalOthersCanReadIsRefusedAndADamagedJournalNamesItsLine) {
  test::TempDir dir;
  const std::string users = dir.file("users");
  ASSERT_TRUE(set_account(users, {"alice", Role::kCommander, *hash_password("correct horse")}).ok());
  test::write_file(dir.file("key"), std::string(64, 'k') + "\n");
  std::filesystem::permissions(dir.file("key"),
                               std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                                   std::filesystem::perms::group_read | std::filesystem::perms::others_read);
  auto refused = Operators::open(users, dir.file("key"), dir.file("sessions"), 1000);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().message,
            dir.file("key") +
                ": the session key is readable or writable by group or others (mode 0644); whoever "
                "reads it can sign in as any operator: chmod 600 " +
                dir.file("key"));
  std::filesystem::permissions(dir.file("key"),
                               std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  ASSERT_TRUE(Operators::open(users, dir.file("key"), dir.file("sessions"), 1000).ok());
  test::write_file(dir.file("sessions"), "# journal\n+ 00 12 alice\n");
  std::filesystem::permissions(dir.file("sessions"),
                               std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  auto damaged = Operators::open(users, dir.file("key"), dir.file("sessions"), 1000);
  ASSERT_FALSE(damaged.ok());
  EXPECT_EQ(damaged.error().message.rfind(dir.file("sessions") + ":2: expected", 0), 0U)
      << damaged.error().message;
}

// Each file others may read or write is refused with what they could do with that file: the audit file
// and the session journal said "whoever reads it can sign in as any operator", which is not so of either
// (the audit file signs no one in; the journal holds keyed hashes, never a session id, but a line written
// into it can give one's own session another user).
TEST(PrivateFiles, EachFileOpenToOthersIsRefusedWithWhatTheyCouldDoWithIt) {
  test::TempDir dir;
  const auto open_to_others = [&](const std::string& name) {
    test::write_file(dir.file(name), "");
    using std::filesystem::perms;
    std::filesystem::permissions(
        dir.file(name), perms::owner_read | perms::owner_write | perms::group_read | perms::others_read);
    return dir.file(name);
  };
  const std::string audit = open_to_others("audit.jsonl");
  EXPECT_EQ(
      AuditLog::open(audit).error().message,
      audit +
          ": the audit file is readable or writable by group or others (mode 0644); whoever reads it learns "
          "who signed in from where and what they commanded, whoever writes it can forge or erase the "
          "record: chmod 600 " +
          audit);
  const std::string journal = open_to_others("sessions");
  EXPECT_EQ(
      SessionStore::open(journal, "key", 1000).error().message,
      journal +
          ": the session journal is readable or writable by group or others (mode 0644); whoever writes it "
          "can sign in as any operator: chmod 600 " +
          journal);
}

// Any bytes in a DDS string (here an operator id and a unit name that are not UTF-8) become text, never an
// exception: nlohmann::json::dump throws on invalid UTF-8, which ended `tetra ground`.
TEST(Encode, StringsThatAreNotUtf8AreShownWithTheReplacementCharacter) {
  nlohmann::json ack = {{"operator", std::string("caf\xe9")}, {std::string("unit\xff"), "x\x80y"}};
  std::string text;
  ASSERT_NO_THROW(text = json_text(ack));
  EXPECT_EQ(text, "{\"operator\":\"caf\xef\xbf\xbd\",\"unit\xef\xbf\xbd\":\"x\xef\xbf\xbdy\"}");
  EXPECT_TRUE(nlohmann::json::accept(text));
}

// The accounts file through a symbolic link is written through it (the link stays); a damaged hash, an
// empty file and a file others can read are refused at start; a password beyond 1024 bytes is refused,
// a final CR is no part of it.
TEST(Operators, LinkedDamagedOrOpenAccountsFiles) {
  test::TempDir dir;
  auto hash = hash_password("correct horse");
  ASSERT_TRUE(hash.ok());
  const std::string real = dir.file("real_users");
  const std::string link = dir.file("users");
  std::filesystem::create_symlink(real, link);
  test::write_file(real, "");
  std::filesystem::permissions(real,
                               std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  EXPECT_EQ(Operators::open(real, dir.file("key"), dir.file("sessions"), 1000).error().message,
            real + ": no accounts (add one with tetra ground passwd USER --users " + real + ")");
  ASSERT_TRUE(set_account(link, {"alice", Role::kCommander, *hash}).ok());
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  ASSERT_EQ(read_accounts(real)->size(), 1U);
  EXPECT_TRUE(Operators::open(link, dir.file("key"), dir.file("sessions"), 1000).ok());
  std::filesystem::permissions(real, std::filesystem::perms::others_read, std::filesystem::perm_options::add);
  EXPECT_EQ(Operators::open(link, dir.file("key"), dir.file("sessions"), 1000).error().message,
            link +
                ": the accounts file is readable or writable by group or others (mode 0604); whoever reads "
                "it can sign in as any operator: chmod 600 " +
                link);
  const std::string cut = dir.file("cut");
  test::write_file(cut, "alice:viewer:" + hash->substr(0, hash->size() - 10) + "\n");
  EXPECT_EQ(read_accounts(cut).error().message,
            cut + ":1: the argon2id hash is damaged (set the password again with tetra ground passwd)");
  test::write_file(cut, "alice:viewer:" + *hash + "\r\n");
  EXPECT_FALSE(read_accounts(cut).ok());
  EXPECT_EQ(hash_password(std::string(kMaxPasswordBytes + 1, 'x')).error().message,
            "password: at most 1024 characters");
  EXPECT_EQ(*password_of_line("correct horse\r"), "correct horse");
  EXPECT_EQ(password_of_line(std::string(10 << 20, 'x')).error().message,
            "password: at most 1024 characters");
  EXPECT_EQ(password_of_line("seven\r").error().message, "password: at least 8 characters");
}

// A users file that is a symbolic link to nothing is refused by name: neither replaced by a file (the link
// lost) nor followed to create a file where it points; a link to a file is still written through.
TEST(PrivateFile, ADanglingLinkIsRefusedNeverReplacedNorFollowed) {
  test::TempDir dir;
  const std::string link = dir.file("users");
  const std::string nowhere = dir.file("gone/users");
  std::filesystem::create_symlink(nowhere, link);
  const Status written = write_private(link, "alice:viewer:x\n");
  ASSERT_FALSE(written.ok());
  EXPECT_EQ(written.error().kind, ErrorKind::kBadInput);
  EXPECT_EQ(written.error().message.rfind(link + ": a symbolic link to no file (", 0), 0U)
      << written.error().message;
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(nowhere)));
  std::filesystem::create_symlink(dir.file("nothing"), dir.file("users2"));
  auto hash = hash_password("correct horse");
  ASSERT_TRUE(hash.ok());
  EXPECT_FALSE(set_account(dir.file("users2"), {"alice", Role::kCommander, *hash}).ok());
  EXPECT_TRUE(std::filesystem::is_symlink(dir.file("users2")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("nothing")));
}

TEST(GroundServer, NoAuthOnlyOnLoopback) {
  EXPECT_TRUE(is_loopback_host("127.0.0.1"));
  EXPECT_TRUE(is_loopback_host("127.1.2.3"));
  EXPECT_TRUE(is_loopback_host("localhost"));
  EXPECT_TRUE(is_loopback_host("::1"));
  EXPECT_FALSE(is_loopback_host("0.0.0.0"));
  EXPECT_FALSE(is_loopback_host("192.168.1.2"));
}

}  // namespace
}  // namespace tetra::ground
