// The ground station's HTTP server in process, without DDS (a fake command sender), through raw
// sockets: sign-in and roles, the cross-site defences (Host, Origin, content type, CSRF token), the
// operator of a command being the signed-in user, validated parameters, the body limit, the bounded
// number of streams, stream ids of the server's run, and the request deadline against slow clients.
// Waits have generous bounds that only turn a hang into a failure; nothing asserts on elapsed time.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "ground_http_client.hpp"
#include "test_support.hpp"
#include "tetra/ground/http_api.hpp"
#include "tetra/ground/operators.hpp"

namespace tetra::ground {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;
using namespace http_test;  // NOLINT(google-build-using-namespace): the tests' client

//! A users file in `dir` with commander alice and viewer victor, both "correct horse"; its configuration.
ServerConfig alice_and_victor(const test::TempDir& dir) {
  auto hash = hash_password("correct horse");
  EXPECT_TRUE(hash.ok());
  if (!hash.ok()) return {};
  EXPECT_TRUE(set_account(dir.file("users"), {"alice", Role::kCommander, *hash}).ok());
  EXPECT_TRUE(set_account(dir.file("users"), {"victor", Role::kViewer, *hash}).ok());
  ServerConfig config;
  config.users_path = dir.file("users");
  return config;
}

TEST(GroundHttp, SignInRolesAndCrossSiteDefences) {
  test::TempDir dir;
  ServerConfig config = alice_and_victor(dir);
  Ground g(config);
  ASSERT_TRUE(g.start().ok());

  // No session: the API says 401, a page goes to the sign-in page.
  EXPECT_EQ(g.request("GET", "/api/units").status, 401);
  const Reply page = g.request("GET", "/");
  EXPECT_EQ(page.status, 302);
  EXPECT_NE(page.head.find("Location: /login.html"), std::string::npos);
  EXPECT_EQ(g.request("GET", "/login.html").status, 200);
  EXPECT_EQ(g.request("POST", "/api/login", kJson, R"({"user":"alice","password":"wrong"})").status, 401);

  const auto sign_in = [&](const std::string& user) {
    const Reply r =
        g.request("POST", "/api/login", kJson, R"({"user":")" + user + R"(","password":"correct horse"})");
    EXPECT_EQ(r.status, 200) << r.body;
    const auto at = r.head.find("Set-Cookie: tetra_session=");
    EXPECT_NE(at, std::string::npos);
    const std::string line = r.head.substr(at, r.head.find("\r\n", at) - at);
    EXPECT_NE(line.find("; HttpOnly"), std::string::npos) << line;
    EXPECT_NE(line.find("; SameSite=Strict"), std::string::npos) << line;
    const std::string cookie = line.substr(12, line.find(';') - 12);
    return std::make_pair("Cookie: " + cookie + "\r\n", r.data()["csrf"].get<std::string>());
  };
  const auto [alice, alice_csrf] = sign_in("alice");
  const auto [victor, victor_csrf] = sign_in("victor");
  const Reply session = g.request("GET", "/api/session", alice);
  EXPECT_EQ(session.data()["user"], "alice");
  EXPECT_EQ(session.data()["role"], "commander");

  const std::string command = R"({"unit":"u","action":"reset"})";
  const std::string alice_token = "X-CSRF-Token: " + alice_csrf + "\r\n";
  // Forged requests as a cross-site page makes them: none reaches the unit.
  EXPECT_EQ(
      g.request("POST", "/api/command", alice + "Content-Type: text/plain\r\n" + alice_token, command).status,
      415);
  EXPECT_EQ(g.request("POST", "/api/command", alice + kJson, command).status, 403);  // no token
  EXPECT_EQ(
      g.request("POST", "/api/command", alice + kJson + "X-CSRF-Token: " + victor_csrf + "\r\n", command)
          .status,
      403);  // another session's token
  EXPECT_EQ(g.request("POST", "/api/command", alice + kJson + alice_token + "Origin: http://evil.example\r\n",
                      command)
                .status,
            403);
  // DNS rebinding: the right address under another name.
  {
    const int fd = connect_to(g.port());
    const std::string req = "GET /api/units HTTP/1.1\r\nHost: evil.example:" + std::to_string(g.port()) +
                            "\r\nConnection: close\r\n" + alice + "\r\n";
    (void)::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    EXPECT_EQ(parse_reply(read_from(fd)).status, 403);
    ::close(fd);
  }
  EXPECT_EQ(
      g.request("POST", "/api/command", victor + kJson + "X-CSRF-Token: " + victor_csrf + "\r\n", command)
          .status,
      403);  // a viewer
  EXPECT_TRUE(g.sent.empty());

  // The commander's command, with the operator the session's user (a typed one is refused).
  EXPECT_EQ(g.request("POST", "/api/command", alice + kJson + alice_token,
                      R"({"unit":"u","action":"reset","operator":"eve"})")
                .status,
            400);
  const Reply ok = g.request("POST", "/api/command",
                             alice + kJson + alice_token + "Origin: http://" + g.host() + "\r\n", command);
  ASSERT_EQ(ok.status, 200) << ok.body;
  ASSERT_EQ(g.sent.size(), 1U);
  EXPECT_EQ(g.sent[0].operator_id, "alice");
  EXPECT_EQ(g.sent[0].origin, "ground@127.0.0.1");
  EXPECT_EQ(ok.data()["operator"], "alice");
  EXPECT_EQ(ok.head.find("Access-Control"), std::string::npos);  // no CORS

  // Signed out: the cookie no longer opens anything.
  EXPECT_EQ(g.request("POST", "/api/logout", alice + kJson + alice_token, "{}").status, 200);
  EXPECT_EQ(g.request("GET", "/api/units", alice).status, 401);
}

TEST(GroundHttp, TheTrustedProxysUserHeaderSignsInOnlyFromTheProxysAddress) {
  test::TempDir dir;
  ServerConfig config = alice_and_victor(dir);
  config.audit_path = dir.file("audit.jsonl");
  config.trusted_proxy_header = "X-Remote-User";
  config.trusted_proxies = {"::ffff:127.0.0.2"};  // the same host as 127.0.0.2
  Ground g(config);
  ASSERT_TRUE(g.start().ok());
  const char* proxy = "127.0.0.2";
  const std::string reset = R"({"unit":"u","action":"reset"})";
  // From the proxy's address: the user it names, with the role of their account, no password.
  const Reply alice = g.request("GET", "/api/session", "X-Remote-User: alice\r\n", "", proxy);
  ASSERT_EQ(alice.status, 200) << alice.body;
  EXPECT_EQ(alice.data()["user"], "alice");
  EXPECT_EQ(alice.data()["role"], "commander");
  EXPECT_EQ(alice.data()["by_proxy"], true);
  const std::string as_alice = "X-Remote-User: alice\r\n" + kJson;
  const std::string csrf = "X-CSRF-Token: " + alice.data()["csrf"].get<std::string>() + "\r\n";
  EXPECT_EQ(g.request("POST", "/api/command", as_alice, reset, proxy).status, 403);  // no CSRF token
  EXPECT_EQ(g.request("POST", "/api/command", as_alice + csrf, reset, proxy).status, 200);
  ASSERT_EQ(g.sent.size(), 1U);
  EXPECT_EQ(g.sent[0].operator_id, "alice");
  // A viewer stays a viewer; a name without an account, or not a user name, is refused.
  const Reply victor = g.request("GET", "/api/session", "X-Remote-User: victor\r\n", "", proxy);
  const std::string as_victor = "X-Remote-User: victor\r\n" + kJson +
                                "X-CSRF-Token: " + victor.data()["csrf"].get<std::string>() + "\r\n";
  EXPECT_EQ(g.request("POST", "/api/command", as_victor, reset, proxy).status, 403);
  const Reply nobody = g.request("GET", "/api/units", "X-Remote-User: mallory\r\n", "", proxy);
  EXPECT_EQ(nobody.status, 403);
  EXPECT_NE(nobody.body.find("has no account"), std::string::npos) << nobody.body;
  EXPECT_EQ(g.request("GET", "/api/units", "X-Remote-User: alice, victor\r\n", "", proxy).status, 403);
  // From any other address the header is refused (and audited), whatever it names.
  for (const char* other : {"127.0.0.1", "127.0.0.3"}) {
    const Reply forged = g.request("POST", "/api/command", as_alice + csrf, reset, other);
    EXPECT_EQ(forged.status, 403) << other;
    EXPECT_NE(forged.body.find("not a --trusted-proxy address"), std::string::npos) << forged.body;
  }
  EXPECT_EQ(g.sent.size(), 1U);
  // From the proxy without the header, or with it empty (nobody signed in there): the ground's own
  // sign-in, as without a proxy.
  EXPECT_EQ(g.request("GET", "/api/units", "", "", proxy).status, 401);
  EXPECT_EQ(g.request("GET", "/api/units", "X-Remote-User:\r\n", "", proxy).status, 401);
  // Signing out is the proxy's: the header still signs alice in.
  EXPECT_EQ(g.request("POST", "/api/logout", as_alice + csrf, "{}", proxy).status, 200);
  EXPECT_EQ(g.request("GET", "/api/units", as_alice, "", proxy).status, 200);
  // Audited: alice's and victor's first sight, the refusals.
  std::ifstream in(config.audit_path);
  int by_proxy = 0;
  int forged = 0;
  for (std::string line; std::getline(in, line);) {
    const json r = json::parse(line);
    by_proxy += r["reason"].get<std::string>().find(
                    "authenticated by the proxy at 127.0.0.2 (X-Remote-User)") != std::string::npos
                    ? 1
                    : 0;
    forged +=
        r["reason"].get<std::string>().find("not a --trusted-proxy address") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(by_proxy, 2);
  EXPECT_EQ(forged, 2);
  // Both options or neither; never with --no-auth.
  for (const auto& [header, address] : {std::pair<std::string, std::string>{"X-Remote-User", ""},
                                        {"", "127.0.0.2"},
                                        {"X-Remote-User", "proxy.example"},
                                        {"X Remote", "127.0.0.2"}}) {
    ServerConfig bad = config;
    bad.trusted_proxy_header = header;
    bad.trusted_proxies = address.empty() ? std::vector<std::string>{} : std::vector<std::string>{address};
    Ground b(bad);
    EXPECT_FALSE(b.start().ok()) << header << " " << address;
  }
}

TEST(GroundHttp, NoAuthIsRefusedOffLoopbackAndNeedsNoAccounts) {
  ServerConfig off;
  off.no_auth = true;
  off.host = "0.0.0.0";
  Ground refused(off);
  EXPECT_FALSE(refused.start().ok());
  ServerConfig none;
  Ground no_accounts(none);  // neither --users nor --no-auth
  EXPECT_FALSE(no_accounts.start().ok());
}

TEST(GroundHttp, ParametersBodiesStreamsAndSlowClientsAreBounded) {
  ServerConfig config;
  config.no_auth = true;
  config.limits.max_streams = 3;
  config.limits.request_timeout_s = 0.5;
  config.allow_origins = {"http://ground.example.org"};
  Ground g(config);
  ASSERT_TRUE(g.start().ok());
  const Reply session = g.request("GET", "/api/session");
  ASSERT_EQ(session.status, 200);
  EXPECT_EQ(session.data()["user"], "anonymous");
  // --allow-origin adds a name; without a port it is the scheme's default, as a browser omits it.
  const auto with_host = [&](const std::string& host) {
    const int fd = connect_to(g.port());
    const std::string req = "GET /api/units HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n";
    (void)::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    const int status = parse_reply(read_from(fd)).status;
    ::close(fd);
    return status;
  };
  EXPECT_EQ(with_host("ground.example.org"), 200);
  EXPECT_EQ(with_host("ground.example.org:80"), 200);
  EXPECT_EQ(with_host("ground.example.org:8443"), 403);
  EXPECT_EQ(with_host("other.example.org"), 403);

  // A negative count was a loop without end: now a 400 naming the parameter.
  const Reply negative = g.request("GET", "/api/history?unit=u&kind=event&max=-1");
  EXPECT_EQ(negative.status, 400);
  EXPECT_NE(negative.body.find("'max'"), std::string::npos) << negative.body;
  EXPECT_EQ(g.request("GET", "/api/history?unit=u&kind=event&start=inf").status, 400);
  EXPECT_EQ(g.request("GET", "/api/history?unit=u&kind=event&what=1").status, 400);
  EXPECT_EQ(g.request("GET", "/api/records?file=a%00.csv").status, 400);

  // A body beyond the limit is refused from its Content-Length, before it is read.
  {
    const int fd = connect_to(g.port());
    const std::string req = "POST /api/command HTTP/1.1\r\nHost: " + g.host() +
                            "\r\nContent-Type: application/json\r\nContent-Length: 268435456\r\n\r\n";
    (void)::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    EXPECT_EQ(parse_reply(read_from(fd)).status, 413);
    ::close(fd);
  }

  // Streams: ids carry this run's instance; three held, the fourth refused with 503.
  dds::HealthView h;
  h.unit = "u";
  h.health_period_s = 0.5;
  g.store().add_health(h, 1'700'000'000'000'000'000, 1);
  std::vector<int> streams;
  std::string first;
  for (int i = 0; i < 3; ++i) {
    const int fd = connect_to(g.port());
    const std::string req = "GET /api/stream HTTP/1.1\r\nHost: " + g.host() + "\r\n\r\n";
    (void)::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    const std::string text = read_from(fd, "event: link");
    EXPECT_NE(text.find("200 OK"), std::string::npos) << text;
    if (i == 0) first = text;
    streams.push_back(fd);
  }
  EXPECT_EQ(g.request("GET", "/api/stream").status, 503);
  EXPECT_EQ(g.request("GET", "/api/units").status, 200);  // the API still answers
  g.store().add_health(h, 1'700'000'000'100'000'000, 2);
  const std::string more = read_from(streams[0], "\n\n");
  const auto id_at = more.find("id: ");
  ASSERT_NE(id_at, std::string::npos) << more;
  const std::string id = more.substr(id_at + 4, more.find('\n', id_at) - id_at - 4);
  EXPECT_NE(id.find('-'), std::string::npos) << id;  // "<instance>-<n>"
  for (const int fd : streams) ::close(fd);
  std::this_thread::sleep_for(200ms);  // the server sees the closes

  // A Last-Event-ID of another run (a restarted ground station): a reset and the current state.
  const int fd = connect_to(g.port());
  const std::string req =
      "GET /api/stream HTTP/1.1\r\nHost: " + g.host() + "\r\nLast-Event-ID: 0badf00d-99999\r\n\r\n";
  (void)::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
  const std::string reset = read_from(fd, "event: link");
  EXPECT_NE(reset.find("event: reset"), std::string::npos) << reset;
  EXPECT_NE(reset.find("event: health"), std::string::npos) << reset;
  ::close(fd);

  // A client sending its request a byte at a time is closed at the request deadline.
  const int slow = connect_to(g.port());
  (void)::send(slow, "GET /api/u", 10, MSG_NOSIGNAL);
  const std::string answer = read_from(slow);  // returns when the server closes (bounded: 10 s)
  EXPECT_EQ(answer.find("200"), std::string::npos);
  ::close(slow);
}

//! [s] until the server closes `fd` (its FIN or reset); -1 when it is still open after the client's 10 s.
double seconds_until_closed(int fd) {
  const auto start = std::chrono::steady_clock::now();
  char byte = 0;
  const ssize_t n = ::recv(fd, &byte, 1, 0);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return n == 0 || (n < 0 && errno == ECONNRESET) ? waited : -1.0;
}

// The idle deadline (HttpLimits::idle_timeout_s, 30 s by default, 2 s here): a connection that sends
// nothing, and a kept-alive one once its answer is out, is closed when it has passed, not before (the
// request deadline, 0.5 s here, counts only from a request's first byte) and not never.
TEST(GroundHttp, AnIdleConnectionIsClosedAtTheIdleDeadline) {
  ServerConfig config;
  config.no_auth = true;
  config.limits.idle_timeout_s = 2.0;
  config.limits.request_timeout_s = 0.5;
  Ground g(config);
  ASSERT_TRUE(g.start().ok());
  const auto at_deadline = [](double waited) {
    // A timer never fires early; the upper bound only turns a hang into a failure on a loaded machine.
    EXPECT_GE(waited, 1.95);
    EXPECT_LT(waited, 7.0);
  };
  const int silent = connect_to(g.port());
  ASSERT_GE(silent, 0);
  at_deadline(seconds_until_closed(silent));
  ::close(silent);

  const int kept = connect_to(g.port());
  ASSERT_GE(kept, 0);
  const std::string req = "GET /api/units HTTP/1.1\r\nHost: " + g.host() + "\r\n\r\n";
  (void)::send(kept, req.data(), req.size(), MSG_NOSIGNAL);
  const Reply answer = parse_reply(read_from(kept, "[]"));
  ASSERT_EQ(answer.status, 200) << answer.head;
  EXPECT_EQ(answer.head.find("Connection: close"), std::string::npos) << answer.head;
  at_deadline(seconds_until_closed(kept));
  ::close(kept);
}

}  // namespace
}  // namespace tetra::ground
