// Integration of the ground station: simulator (sim --dds) + fusion service + tetra ground
// as separate processes on a private loopback domain; an HTTP client reads the event stream and the
// history, and commands through POST; and a DDS peer of another make, in this process, whose unit names
// are not UTF-8, reached by their unit ids. Waits have generous upper bounds that only turn a hang into a
// failure; nothing asserts on elapsed time.

#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/session.hpp"
#include "tetra_process.hpp"
// After Eigen (through the headers above): httplib.h brings <resolv.h>, whose `_res` macro breaks Eigen.
#include <httplib.h>

namespace tetra::test {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

const bool kLoopback = use_loopback_dds();

//! One server-sent event.
struct Sse {
  std::uint64_t id = 0;  //!< the number after the server run's prefix ("<instance>-<n>")
  std::string id_text;
  std::string event;
  json data;
};

//! Parses the text of an event stream as it arrives.
class SseParser {
 public:
  void feed(const char* data, std::size_t n, std::vector<Sse>& out) {
    buffer_.append(data, n);
    for (auto end = buffer_.find("\n\n"); end != std::string::npos; end = buffer_.find("\n\n")) {
      Sse e;
      std::istringstream block(buffer_.substr(0, end));
      buffer_.erase(0, end + 2);
      std::string line;
      while (std::getline(block, line)) {
        if (line.rfind("id: ", 0) == 0) {
          e.id_text = line.substr(4);
          e.id = std::stoull(e.id_text.substr(e.id_text.find('-') + 1));
        }
        if (line.rfind("event: ", 0) == 0) e.event = line.substr(7);
        if (line.rfind("data: ", 0) == 0) e.data = json::parse(line.substr(6), nullptr, false);
      }
      if (!e.event.empty()) out.push_back(std::move(e));
    }
  }

 private:
  std::string buffer_;
};

//! Reads /api/stream (optionally resuming after `last_id`) until `done` holds or `limit` passes.
std::vector<Sse> read_stream(int port, const std::function<bool(const std::vector<Sse>&)>& done,
                             const std::string& last_id = "", std::chrono::seconds limit = 60s) {
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(5, 0);
  std::vector<Sse> events;
  SseParser parser;
  const auto give_up = std::chrono::steady_clock::now() + limit;
  httplib::Headers headers;
  if (!last_id.empty()) headers.emplace("Last-Event-ID", last_id);
  (void)client.Get("/api/stream", headers, [&](const char* data, std::size_t n) {
    parser.feed(data, n, events);
    return !done(events) && std::chrono::steady_clock::now() < give_up;
  });
  return events;
}

//! The port `tetra ground` printed in its log ("tetra ground: http://127.0.0.1:PORT/").
int ground_port(const std::string& log_path) {
  const std::regex url(R"(http://127\.0\.0\.1:(\d+)/)");
  for (int attempt = 0; attempt < 200; ++attempt) {
    std::smatch m;
    const std::string log = read_file(log_path);
    if (std::regex_search(log, m, url)) return std::stoi(m[1]);
    std::this_thread::sleep_for(50ms);
  }
  return -1;
}

bool health_with(const std::vector<Sse>& events, const std::string& mode) {
  for (const auto& e : events) {
    if (e.event == "health" && e.data.value("mode", "") == mode) return true;
  }
  return false;
}

//! A command as the page posts it: JSON with the session's CSRF token (--no-auth: one per run).
json post_command(int port, const json& body, int& status) {
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(10, 0);
  auto session = client.Get("/api/session");
  const json s = session ? json::parse(session->body, nullptr, false) : json();
  httplib::Headers headers{{"X-CSRF-Token", s.is_object() ? s.value("csrf", "") : ""}};
  auto res = client.Post("/api/command", headers, body.dump(), "application/json");
  status = res ? res->status : -1;
  return res ? json::parse(res->body, nullptr, false) : json();
}

TEST(GroundStation, StreamHistoryCommandsAndStaleness) {
  const int domain = 181;
  const std::string d = std::to_string(domain);
  TempDir dir;
  Calibration cal = seed_as_built_unit();
  cal.unit = "tetra-1";
  ASSERT_TRUE(write_calibration(dir.file("cal.yaml"), cal).ok());
  write_file(dir.file("fusion.yaml"),
             "unit: tetra-1\ncalibration: cal.yaml\nsample_rate_hz: 100\nspeed: 1\nmax_latency_s: 0.05\n"
             "health_period_s: 0.2\n");
  auto fusion = std::make_unique<TetraProcess>(
      std::vector<std::string>{"fusion", "--config", dir.file("fusion.yaml"), "--domain", d},
      dir.file("fusion.log"));
  TetraProcess ground({"ground", "--listen", "127.0.0.1:0", "--no-auth", "--domain", d},
                      dir.file("ground.log"));
  const int port = ground_port(dir.file("ground.log"));
  ASSERT_GT(port, 0) << read_file(dir.file("ground.log"));
  // 40 s of orbit at 100 Hz, 4 times real time; gyro 2 stuck from 8 s (2 s of wall clock).
  TetraProcess sim({"sim", "orbit", "--dds", "--dds-unit", "tetra-1", "--domain", d, "--rate-hz", "100",
                    "--minutes", "0.67", "--reference-hz", "0", "--speed", "4", "--fault",
                    "gyro=2,kind=stuck,at=8", "--wait-readers", "1"},
                   dir.file("sim.log"));

  // The stream: NOMINAL first, then the isolation of gyro 2 and DEGRADED.
  const auto events = read_stream(port, [](const std::vector<Sse>& ev) {
    bool isolated = false;
    for (const auto& e : ev)
      isolated = isolated || (e.event == "event" && e.data.value("event", "") == "isolated");
    return isolated && health_with(ev, "DEGRADED");
  });
  ASSERT_TRUE(health_with(events, "NOMINAL")) << read_file(dir.file("ground.log"));
  ASSERT_TRUE(health_with(events, "DEGRADED")) << read_file(dir.file("fusion.log"));
  std::uint64_t attitude_count = 0;
  std::uint64_t last_id = 0;
  std::string instance;
  for (const auto& e : events) {
    attitude_count += e.event == "attitude" ? 1 : 0;
    if (e.event == "attitude") {
      EXPECT_EQ(e.data["q"].size(), 4U);
      EXPECT_TRUE(e.data["euler_deg"].contains("yaw"));
      EXPECT_GT(e.data["utc_ms"].get<double>(), 1.7e12);  // a UTC time (after 2023), not sensor time
    }
    if (e.id != 0) {
      last_id = e.id;
      instance = e.id_text.substr(0, e.id_text.find('-') + 1);
    }
  }
  EXPECT_GT(attitude_count, 5U);
  ASSERT_GT(last_id, 10U);

  // Resuming after an id gives the messages after it, in order.
  const auto resumed = read_stream(
      port, [](const std::vector<Sse>& ev) { return ev.size() >= 3; }, instance + std::to_string(last_id - 5),
      10s);
  ASSERT_GE(resumed.size(), 3U);
  EXPECT_EQ(resumed[0].id, last_id - 4);
  EXPECT_EQ(resumed[1].id, last_id - 3);

  // History: attitude decimated to 10 Hz of sensor time, events with the isolation.
  httplib::Client client("127.0.0.1", port);
  auto attitude = client.Get("/api/history?unit=tetra-1&kind=attitude&max=100000");
  ASSERT_TRUE(attitude && attitude->status == 200);
  const json rows = json::parse(attitude->body);
  ASSERT_GT(rows.size(), 10U);
  // Never closer than 0.1 s of sensor time (less half a 100 Hz sample of slack); mostly exactly 0.1 s
  // apart: Attitude is keep-last 1, so a loaded machine may skip a sample and make a gap a bit longer.
  std::size_t exact = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double dt = rows[i]["sensor_time_s"].get<double>() - rows[i - 1]["sensor_time_s"].get<double>();
    EXPECT_GE(dt, 0.0949) << i;
    exact += std::abs(dt - 0.1) < 1e-3 ? 1 : 0;
  }
  EXPECT_GE(exact, (rows.size() - 1) * 8 / 10) << "fewer than 80 % of the gaps are 0.1 s";
  auto history_events = client.Get("/api/history?unit=tetra-1&kind=event");
  ASSERT_TRUE(history_events && history_events->status == 200);
  EXPECT_NE(history_events->body.find("\"isolated\""), std::string::npos);
  // The isolation arrived over DDS with the ledger rows that decided it: gyro 2's hypothesis consistent,
  // every other gyro's rejected, and the rule rebuilt from the rows names gyro 2.
  bool explained = false;
  for (const auto& ev : json::parse(history_events->body)) {
    if (ev.value("event", "") != "isolated") continue;
    std::map<std::string, std::string> verdict;
    for (const auto& row : ev["ledger"]) verdict[row["hypothesis"].get<std::string>()] = row["verdict"];
    explained = verdict["H2"] == "consistent" && verdict["H1"] == "rejected" && verdict["H3"] == "rejected" &&
                verdict["H4"] == "rejected" && verdict["H0"] == "rejected";
  }
  EXPECT_TRUE(explained) << history_events->body;
  auto unknown = client.Get("/api/history?unit=nobody&kind=event");
  ASSERT_TRUE(unknown);
  EXPECT_EQ(unknown->status, 404);

  // Commands, with gyro 2 isolated and 1, 3, 4 in use: excluding another would leave two gyros,
  // which cannot determine the rate: refused, through POST and from the command line (exit 1); with
  // force, obeyed (the unit goes LOST); the FDI reset is accepted; a malformed request is a 400.
  int status = 0;
  json ack = post_command(port, {{"unit", "tetra-1"}, {"action", "exclude"}, {"gyro", 1}}, status);
  ASSERT_EQ(status, 200) << ack.dump();
  EXPECT_FALSE(ack["accepted"].get<bool>()) << ack.dump();
  EXPECT_NE(ack["detail"].get<std::string>().find("refused"), std::string::npos) << ack.dump();
  EXPECT_EQ(ack["operator"], "anonymous");  // --no-auth: nobody signed in
  EXPECT_EQ(ack["origin"], "ground@127.0.0.1");
  const auto refused = run_tetra("command --unit tetra-1 exclude 3 --operator test --domain " + d);
  EXPECT_EQ(refused.exit_status, 1) << refused.out << refused.err;
  EXPECT_NE(refused.out.find("\"accepted\": false"), std::string::npos) << refused.out;
  EXPECT_NE(refused.out.find("\"operator\": \"test\""), std::string::npos) << refused.out;
  EXPECT_NE(refused.err.find("refused"), std::string::npos) << refused.err;
  const auto forced = run_tetra("command --unit tetra-1 exclude 3 --force --operator test --domain " + d);
  EXPECT_EQ(forced.exit_status, 0) << forced.err << forced.out;
  EXPECT_NE(forced.out.find("\"force\": true"), std::string::npos) << forced.out;
  ack = post_command(port, {{"unit", "tetra-1"}, {"action", "reset"}}, status);
  ASSERT_EQ(status, 200) << ack.dump();
  EXPECT_TRUE(ack["accepted"].get<bool>()) << ack.dump();
  (void)post_command(port, {{"unit", "tetra-1"}, {"action", "exclude"}}, status);
  EXPECT_EQ(status, 400);

  // An operator id that is not UTF-8 (any DDS writer may send one; \351 is Latin-1's e-acute): the ground
  // shows it with the replacement character and lives on; it ended `tetra ground` with a JSON exception.
  const auto odd =
      run_tetra("command --unit tetra-1 reset --operator \"$(printf 'caf\\351')\" --domain " + d);
  EXPECT_EQ(odd.exit_status, 0) << odd.err << odd.out;
  // The acknowledgement reaches the ground over DDS after the command returns: wait for it (up to 10 s on a
  // loaded machine; it takes milliseconds on an idle one).
  const std::string shown = "\"operator\":\"caf\xef\xbf\xbd\"";
  auto after_odd = client.Get("/api/history?unit=tetra-1&kind=event");
  for (int i = 0;
       i < 100 && after_odd && after_odd->status == 200 && after_odd->body.find(shown) == std::string::npos;
       ++i) {
    std::this_thread::sleep_for(100ms);
    after_odd = client.Get("/api/history?unit=tetra-1&kind=event");
  }
  ASSERT_TRUE(after_odd && after_odd->status == 200) << read_file(dir.file("ground.log"));
  EXPECT_NE(after_odd->body.find(shown), std::string::npos) << after_odd->body;
  // A second ground started while the service still holds that acknowledgement (transient local) starts.
  TetraProcess ground2({"ground", "--listen", "127.0.0.1:0", "--no-auth", "--domain", d},
                       dir.file("ground2.log"));
  const int port2 = ground_port(dir.file("ground2.log"));
  ASSERT_GT(port2, 0) << read_file(dir.file("ground2.log"));
  std::this_thread::sleep_for(1s);  // time for the held acknowledgements to arrive
  auto served = httplib::Client("127.0.0.1", port2).Get("/api/units");
  EXPECT_TRUE(served && served->status == 200) << read_file(dir.file("ground2.log"));
  EXPECT_EQ(ground2.signal_and_wait(SIGTERM), 0) << read_file(dir.file("ground2.log"));

  // kill -9 of the service: the ground says STALE (or SERVICE LOST) within a few Health periods.
  fusion->kill_now(SIGKILL);
  const auto lost = read_stream(
      port,
      [](const std::vector<Sse>& ev) {
        for (const auto& e : ev) {
          if (e.event == "link" && e.data.value("state", "") != "LIVE" &&
              e.data.value("state", "") != "WAITING")
            return true;
        }
        return false;
      },
      "", 20s);
  bool stale = false;
  for (const auto& e : lost) stale = stale || (e.event == "link" && e.data.value("state", "") != "LIVE");
  EXPECT_TRUE(stale);
  EXPECT_EQ(ground.signal_and_wait(SIGTERM), 0) << read_file(dir.file("ground.log"));
}

//! A unit as a DDS peer of another make may publish it, from this process: Health and Attitude under
//! `name` (any bytes: tetra's own tools refuse a name that is not UTF-8) every 200 ms, and an
//! acknowledgement (reset done) of every Command to that name.
class ForeignUnit {
 public:
  ForeignUnit(int domain, std::string name)
      : name_(std::move(name)), thread_([this, domain] { serve(domain); }) {}
  ~ForeignUnit() {
    stop_ = true;
    thread_.join();
  }
  ForeignUnit(const ForeignUnit&) = delete;
  ForeignUnit& operator=(const ForeignUnit&) = delete;
  //! The unit of each Command received (as its bytes), and the operator it carried.
  std::vector<std::pair<std::string, std::string>> commands() const {
    const std::lock_guard lock(mutex_);
    return commands_;
  }

 private:
  void serve(int domain) {
    auto session = dds::Session::open(domain);
    ASSERT_TRUE(session.ok()) << session.error().message;
    auto health = session->writer<tetra_Health>(dds::health_qos());
    auto attitude = session->writer<tetra_Attitude>(dds::attitude_writer_qos());
    auto events = session->writer<tetra_FdiEvent2>(dds::event_qos());
    auto commands = session->reader<tetra_Command>(dds::command_qos());
    ASSERT_TRUE(health.ok() && attitude.ok() && events.ok() && commands.ok());
    for (int tick = 0; !stop_; ++tick) {
      if (tick % 10 == 0) publish(*health, *attitude, tick);
      auto taken =
          commands->take([&](const tetra_Command& c, const dds_sample_info_t&) { answer(*events, c); });
      ASSERT_TRUE(taken.ok()) << taken.error().message;
      std::this_thread::sleep_for(20ms);
    }
  }
  void publish(const dds::Writer<tetra_Health>& health, const dds::Writer<tetra_Attitude>& attitude,
               int tick) {
    fdi::Health h;
    h.stamp_ns = std::int64_t{tick} * 20'000'000;
    h.gyros.resize(4);
    h.used = 0b1111;
    h.counters.epochs_accepted = static_cast<std::uint64_t>(tick);
    dds::WireHealth wire;
    ASSERT_TRUE(dds::to_wire(name_, h, {}, wire).ok());
    wire.msg.health_period_s = 0.2;
    ASSERT_TRUE(health.write(wire.msg).ok());
    fdi::AttitudeEstimate a;
    a.stamp_ns = h.stamp_ns;
    tetra_Attitude att{};
    ASSERT_TRUE(dds::to_wire(name_, a, att).ok());
    ASSERT_TRUE(attitude.write(att).ok());
  }
  void answer(const dds::Writer<tetra_FdiEvent2>& events, const tetra_Command& c) {
    const std::string unit = dds::from_wire(c.unit);
    {
      const std::lock_guard lock(mutex_);
      commands_.emplace_back(unit, dds::from_wire(c.operator_id));
    }
    if (unit != name_) return;
    dds::EventView ack{name_,
                       ++event_seq_,
                       c.command_id,
                       {},
                       {c.kind, c.force, dds::from_wire(c.operator_id), dds::from_wire(c.origin)}};
    ack.event.type = fdi::EventType::kCommand;
    ack.event.command = fdi::CommandVerb::kReset;
    ack.event.detail = "reset: done";
    dds::WireEvent wire;
    ASSERT_TRUE(dds::to_wire(ack, wire).ok());
    ASSERT_TRUE(events.write(wire.msg).ok());
  }

  std::string name_;
  std::atomic<bool> stop_{false};
  std::uint64_t event_seq_ = 0;
  mutable std::mutex mutex_;
  std::vector<std::pair<std::string, std::string>> commands_;
  std::thread thread_;
};

//! GET `path` until `done` holds of the answer (or 20 s pass); the last answer.
httplib::Result get_until(httplib::Client& client, const std::string& path,
                          const std::function<bool(const httplib::Response&)>& done) {
  auto res = client.Get(path);
  for (int i = 0; i < 200 && !(res && done(*res)); ++i) {
    std::this_thread::sleep_for(100ms);
    res = client.Get(path);
  }
  return res;
}

// A unit whose DDS key is not UTF-8 (\351 is Latin-1's e-acute; \350 e-grave looks the same once shown):
// the ground showed it as "caf\uFFFD", but kept it under its bytes, and the only way to name it, the name
// in a parameter or a command, refused it (not UTF-8) or named another unit: its history and commands were
// out of reach. Every unit has its unit_id, the hexadecimal of its bytes, and is reached by it.
TEST(GroundStation, AUnitWhoseKeyIsNotUtf8IsReachedByItsUnitId) {
  const int domain = 182;
  const std::string d = std::to_string(domain);
  TempDir dir;
  TetraProcess ground({"ground", "--listen", "127.0.0.1:0", "--no-auth", "--domain", d},
                      dir.file("ground.log"));
  const int port = ground_port(dir.file("ground.log"));
  ASSERT_GT(port, 0) << read_file(dir.file("ground.log"));
  const std::string latin = "caf\xe9";
  ForeignUnit cafe(domain, latin);
  ForeignUnit other(domain, "caf\xe8");
  const std::string id = "636166e9";
  const std::string shown = "caf\xef\xbf\xbd";  // U+FFFD

  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(10, 0);
  const auto units = get_until(client, "/api/units", [](const httplib::Response& r) {
    const json j = json::parse(r.body, nullptr, false);
    return j.is_array() && j.size() == 2;
  });
  ASSERT_TRUE(units && units->status == 200) << read_file(dir.file("ground.log"));
  const json listed = json::parse(units->body);
  ASSERT_EQ(listed.size(), 2U) << units->body;
  std::set<std::string> ids;
  for (const auto& u : listed) {
    EXPECT_EQ(u["unit"], shown);  // the two look alike
    ids.insert(u.value("unit_id", ""));
  }
  EXPECT_EQ(ids, (std::set<std::string>{"636166e8", id}));

  // The name itself cannot be sent (a parameter must be UTF-8); the id reaches the unit's own history.
  EXPECT_EQ(client.Get("/api/history?unit=caf%E9&kind=health")->status, 400);
  for (const char* kind : {"health", "attitude"}) {
    const auto rows = get_until(client, "/api/history?unit_id=" + id + "&kind=" + kind,
                                [](const httplib::Response& r) { return r.status == 200 && r.body != "[]"; });
    ASSERT_TRUE(rows && rows->status == 200) << kind;
    for (const auto& row : json::parse(rows->body)) EXPECT_EQ(row["unit_id"], id) << kind << rows->body;
  }

  // A command by the id goes to the unit's own key; its acknowledgement comes back and into the history.
  int status = 0;
  const json ack = post_command(port, {{"unit_id", id}, {"action", "reset"}}, status);
  ASSERT_EQ(status, 200) << ack.dump() << read_file(dir.file("ground.log"));
  EXPECT_TRUE(ack["accepted"].get<bool>()) << ack.dump();
  EXPECT_EQ(ack["unit_id"], id);
  EXPECT_EQ(ack["unit"], shown);
  const auto received = cafe.commands();
  ASSERT_EQ(received.size(), 1U);
  EXPECT_EQ(received[0].first, latin);
  const auto events =
      get_until(client, "/api/history?unit_id=" + id + "&kind=event", [&](const httplib::Response& r) {
        return r.body.find(ack["command_id"].get<std::string>()) != std::string::npos;
      });
  ASSERT_TRUE(events && events->status == 200);
  EXPECT_NE(events->body.find(ack["command_id"].get<std::string>()), std::string::npos) << events->body;
  // The stream carries the id with every message of the unit.
  const auto of_cafe = [&](const std::vector<Sse>& ev) {
    for (const auto& e : ev) {
      if (e.event == "health" && e.data.value("unit_id", "") == id) return true;
    }
    return false;
  };
  EXPECT_TRUE(of_cafe(read_stream(port, of_cafe, "", 20s)));
  EXPECT_EQ(ground.signal_and_wait(SIGTERM), 0) << read_file(dir.file("ground.log"));
}

}  // namespace
}  // namespace tetra::test
