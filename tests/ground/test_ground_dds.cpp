// Integration of the ground station: simulator (sim --dds) + fusion service + tetra ground
// as separate processes on a private loopback domain; an HTTP client reads the event stream and the
// history, and commands through POST. Waits have generous upper bounds that only turn a hang into a
// failure; nothing asserts on elapsed time.

#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
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

}  // namespace
}  // namespace tetra::test
