// Attacks on the ground station's HTTP server in process, through raw sockets (docs/ground.md, threat
// model): password guessing from one address and from many, the audit file and the log against forged
// lines, requests two readers could read differently (a space before a colon, bare LF, obs-fold), bytes
// that are not UTF-8, HEAD and 405, a request followed by FIN, a client that sends but never reads, one
// that reads a byte now and then, and one address holding every connection. Waits have generous bounds
// that only turn a hang into a failure.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "ground_http_client.hpp"
#include "test_support.hpp"
#include "tetra/ground/login_throttle.hpp"
#include "tetra/ground/operators.hpp"

namespace tetra::ground {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;
using namespace http_test;  // NOLINT(google-build-using-namespace): the tests' client

//! Raw bytes on a new connection; the answer up to the server's close.
Reply raw(const Ground& g, const std::string& bytes, bool fin = false) {
  const int fd = connect_to(g.port());
  (void)::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  if (fin) ::shutdown(fd, SHUT_WR);
  Reply r = parse_reply(read_from(fd));
  ::close(fd);
  return r;
}

std::string login_body(const std::string& user, const std::string& password) {
  return json{{"user", user}, {"password", password}}.dump();
}

struct Accounts {
  test::TempDir dir;
  ServerConfig config;
  Accounts() {
    auto hash = hash_password("correct horse");
    EXPECT_TRUE(hash.ok());
    EXPECT_TRUE(set_account(dir.file("users"), {"alice", Role::kCommander, *hash}).ok());
    config.users_path = dir.file("users");
  }
};

TEST(GroundAttacks, AGuesserBacksOffAndNeverLocksTheOperatorOutFromAnotherAddress) {
  Accounts a;
  a.config.throttle.account_max = 8;  // the default 100, smaller to reach it quickly
  Ground g(a.config);
  ASSERT_TRUE(g.start().ok());
  const auto sign_in = [&](const char* from, const std::string& password) {
    return g.request("POST", "/api/login", kJson, login_body("alice", password), from);
  };
  // Alice's own workstation, 127.0.0.2, signs in once: an address the account is known from.
  ASSERT_EQ(sign_in("127.0.0.2", "correct horse").status, 200);
  // A guesser on 127.0.0.1: five failures free, then it waits (429, Retry-After), no password checked,
  // the right password included.
  for (int i = 0; i < 5; ++i) EXPECT_EQ(sign_in("127.0.0.1", "guess" + std::to_string(i)).status, 401);
  const Reply backed_off = sign_in("127.0.0.1", "guess5");
  EXPECT_EQ(backed_off.status, 429) << backed_off.body;
  EXPECT_NE(backed_off.head.find("Retry-After: 1"), std::string::npos) << backed_off.head;
  EXPECT_EQ(sign_in("127.0.0.1", "correct horse").status, 429);
  // Meanwhile the operator signs in from another address, even one the account was never used from.
  EXPECT_EQ(sign_in("127.0.0.3", "correct horse").status, 200);
  // Guessers on more addresses take the account to its cap (8 here): it is locked for new addresses...
  for (int i = 0; i < 3; ++i) EXPECT_EQ(sign_in("127.0.0.4", "more" + std::to_string(i)).status, 401);
  const Reply locked = sign_in("127.0.0.5", "correct horse");
  EXPECT_EQ(locked.status, 429) << locked.body;
  EXPECT_NE(locked.body.find("account locked"), std::string::npos) << locked.body;
  // ...but not for the addresses it signed in from.
  EXPECT_EQ(sign_in("127.0.0.2", "correct horse").status, 200);
  EXPECT_EQ(sign_in("127.0.0.3", "correct horse").status, 200);
}

TEST(LoginThrottle, BackOffDoublesTheCapHoldsForAnHourAndAddressesAreKeyedByHost) {
  LoginThrottle t;  // the defaults: 5 free, 1 s doubling to 60 s, 100 an hour per account
  constexpr std::int64_t kS = 1'000'000'000;
  std::int64_t now = 1000 * kS;
  const auto attempt = [&](const std::string& user, const std::string& from) {
    const auto v = t.admit(user, from, now);
    if (v.allowed) t.record(user, from, false, now);
    return v;
  };
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(attempt("alice", "10.0.0.1").allowed);
  auto v = attempt("alice", "10.0.0.1");
  EXPECT_FALSE(v.allowed);
  EXPECT_NEAR(v.retry_after_s, 1.0, 1e-9);
  now += kS;
  EXPECT_TRUE(attempt("alice", "10.0.0.1").allowed);  // 6 failures: next 2 s after
  now += kS;
  EXPECT_FALSE(attempt("alice", "10.0.0.1").allowed);
  now += kS;
  EXPECT_TRUE(attempt("alice", "10.0.0.1").allowed);
  // One address in an hour: 5, then 1, 2, 4, 8, 16, 32 s apart, then a minute apart.
  int checked = 7;
  for (const std::int64_t end = 1000 * kS + 3600 * kS; now < end; now += kS / 4) {
    checked += attempt("alice", "10.0.0.1").allowed ? 1 : 0;
  }
  EXPECT_LE(checked, 70);
  EXPECT_GE(checked, 60);
  // Many addresses take bob to 100 failures: locked for a new address, not for one bob signed in from.
  const std::int64_t start = now;
  ASSERT_TRUE(t.admit("bob", "10.1.0.1", now).allowed);
  t.record("bob", "10.1.0.1", true, now);
  for (int i = 0; i < 100; ++i) EXPECT_TRUE(attempt("bob", "10.2.0." + std::to_string(i)).allowed);
  v = attempt("bob", "10.3.0.1");
  EXPECT_FALSE(v.allowed);
  EXPECT_NE(v.reason.find("account locked"), std::string::npos);
  EXPECT_TRUE(t.admit("bob", "10.1.0.1", now).allowed);
  t.record("bob", "10.1.0.1", true, now);
  now = start + 3601 * kS;  // the hour has passed
  EXPECT_TRUE(attempt("bob", "10.3.0.1").allowed);
  // IPv6 by its /64 (one host holds a whole one); IPv4, mapped or not, by the whole address.
  EXPECT_EQ(LoginThrottle::address_key("2001:db8::1"), LoginThrottle::address_key("2001:db8::ffff:1"));
  EXPECT_NE(LoginThrottle::address_key("2001:db8::1"), LoginThrottle::address_key("2001:db8:0:1::1"));
  EXPECT_NE(LoginThrottle::address_key("::ffff:10.0.0.1"), LoginThrottle::address_key("::ffff:10.0.0.2"));
  EXPECT_EQ(LoginThrottle::address_key("10.0.0.1"), "10.0.0.1");
}

TEST(GroundAttacks, PasswordChecksNeverBlockOtherSignInsOrTheApi) {
  Accounts a;
  Ground g(a.config);
  ASSERT_TRUE(g.start().ok());
  const Reply alice =
      g.request("POST", "/api/login", kJson, login_body("alice", "correct horse"), "127.0.0.9");
  ASSERT_EQ(alice.status, 200);
  const auto at = alice.head.find("tetra_session=");
  const std::string cookie = "Cookie: " + alice.head.substr(at, alice.head.find(';', at) - at) + "\r\n";
  // Four guessers on four addresses, each as fast as it is answered (the try-lock made other sign-ins 503).
  std::atomic<bool> stop{false};
  std::atomic<int> guesses{0};
  std::vector<std::thread> guessers;
  for (int k = 0; k < 4; ++k) {
    guessers.emplace_back([&, k] {
      const std::string from = "127.0.1." + std::to_string(k + 1);
      for (int i = 0; !stop && i < 5; ++i) {
        g.request("POST", "/api/login", kJson, login_body("alice", "nope" + std::to_string(i)), from.c_str());
        ++guesses;
      }
    });
  }
  std::this_thread::sleep_for(100ms);
  int api_ok = 0;
  for (int i = 0; i < 20; ++i) api_ok += g.request("GET", "/api/units", cookie).status == 200 ? 1 : 0;
  const Reply during =
      g.request("POST", "/api/login", kJson, login_body("alice", "correct horse"), "127.0.0.9");
  stop = true;
  for (auto& t : guessers) t.join();
  EXPECT_EQ(api_ok, 20);
  EXPECT_EQ(during.status, 200) << during.body;  // queued behind the checks, never 503
}

// The sign-in lane's bounds as docs/ground.md states them: 32 sign-ins waiting or checked, 2 of one
// address (here 7, with one worker, so a few fill it). Sign-ins sent at once: the third of one address is a
// 429; a guesser on many addresses fills the lane, and every sign-in beyond it is a 503 (nothing checked).
TEST(GroundAttacks, TheSignInLaneHoldsAFixedNumberAndTwoOfOneAddress) {
  EXPECT_EQ(HttpLimits{}.max_slow_queued, 32U);
  EXPECT_EQ(HttpLimits{}.max_slow_per_address, 2U);
  EXPECT_EQ(HttpLimits{}.slow_workers, 2);
  Accounts a;
  a.config.limits.max_slow_queued = 7;
  a.config.limits.slow_workers = 1;
  Ground g(a.config);
  ASSERT_TRUE(g.start().ok());
  const auto send_login = [&](const std::string& from) {
    const int fd = connect_to(g.port(), from.c_str());
    const std::string body = login_body("alice", "guess");
    const std::string req = "POST /api/login HTTP/1.1\r\nHost: " + g.host() + "\r\nConnection: close\r\n" +
                            kJson + "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
    (void)::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    return fd;
  };
  std::vector<int> one_address;
  for (int i = 0; i < 3; ++i) one_address.push_back(send_login("127.0.2.1"));
  std::this_thread::sleep_for(10ms);  // admitted before the rest (a check takes far longer)
  std::vector<int> many;
  for (int k = 2; k <= 7; ++k) {
    for (int i = 0; i < 2; ++i) many.push_back(send_login("127.0.2." + std::to_string(k)));
  }
  const auto statuses = [](const std::vector<int>& fds) {
    std::multiset<int> out;
    for (const int fd : fds) {
      out.insert(parse_reply(read_from(fd)).status);
      ::close(fd);
    }
    return out;
  };
  EXPECT_EQ(statuses(one_address), (std::multiset<int>{401, 401, 429}));
  // 2 of the lane's 7 held by the first address: 5 of these 12 admitted, the rest 503 unless a check
  // ended meanwhile.
  const auto answered = statuses(many);
  EXPECT_EQ(answered.count(401) + answered.count(503), 12U);
  EXPECT_GE(answered.count(503), 1U);
  EXPECT_LE(answered.count(401), 10U);
}

TEST(GroundHttp, AForcedExclusionWaitsForASecondCommander) {
  Accounts a;
  auto hash = hash_password("correct horse");
  ASSERT_TRUE(set_account(a.dir.file("users"), {"bob", Role::kCommander, *hash}).ok());
  ASSERT_TRUE(set_account(a.dir.file("users"), {"victor", Role::kViewer, *hash}).ok());
  a.config.approval_timeout_s = 1.0;
  Ground g(a.config);
  ASSERT_TRUE(g.start().ok());
  const auto sign_in = [&](const std::string& user) {
    const Reply r = g.request("POST", "/api/login", kJson, login_body(user, "correct horse"));
    EXPECT_EQ(r.status, 200);
    const auto at = r.head.find("tetra_session=");
    return "Cookie: " + r.head.substr(at, r.head.find(';', at) - at) + "\r\n" + kJson +
           "X-CSRF-Token: " + r.data()["csrf"].get<std::string>() + "\r\n";
  };
  const std::string alice = sign_in("alice");
  const std::string bob = sign_in("bob");
  const std::string victor = sign_in("victor");
  const std::string force = R"({"unit":"u","action":"exclude","gyro":3,"force":true})";
  const Reply held = g.request("POST", "/api/command", alice, force);
  ASSERT_EQ(held.status, 202) << held.body;
  EXPECT_TRUE(g.sent.empty());  // not sent before the approval
  const std::string id = held.data()["pending"].get<std::string>();
  const Reply listed = g.request("GET", "/api/pending", alice);
  ASSERT_EQ(listed.data().size(), 1U);
  EXPECT_EQ(listed.data()[0]["operator"], "alice");
  const std::string approval = json{{"id", id}}.dump();
  EXPECT_EQ(g.request("POST", "/api/approve", alice, approval).status, 403);   // her own
  EXPECT_EQ(g.request("POST", "/api/approve", victor, approval).status, 403);  // a viewer
  EXPECT_TRUE(g.sent.empty());
  const Reply approved = g.request("POST", "/api/approve", bob, approval);
  ASSERT_EQ(approved.status, 200) << approved.body;
  ASSERT_EQ(g.sent.size(), 1U);
  EXPECT_TRUE(g.sent[0].force);
  EXPECT_EQ(g.sent[0].operator_id, "alice");
  EXPECT_EQ(approved.data()["approved_by"], "bob");
  EXPECT_EQ(g.request("POST", "/api/approve", bob, approval).status, 404);  // once only
  // One not approved in time is gone; one without force goes at once.
  const Reply late = g.request("POST", "/api/command", alice, force);
  ASSERT_EQ(late.status, 202);
  std::this_thread::sleep_for(1200ms);
  EXPECT_EQ(g.request("POST", "/api/approve", bob, json{{"id", late.data()["pending"]}}.dump()).status, 404);
  EXPECT_EQ(g.request("POST", "/api/command", alice, R"({"unit":"u","action":"exclude","gyro":3})").status,
            200);
  EXPECT_EQ(g.sent.size(), 2U);
}

TEST(GroundHttp, PermissionsGrantCommandsPerUnitAndPerOperator) {
  Accounts a;
  auto hash = hash_password("correct horse");
  ASSERT_TRUE(set_account(a.dir.file("users"), {"bob", Role::kCommander, *hash}).ok());
  {
    std::ofstream f(a.dir.file("permissions"));
    f << "# who:unit:commands\n@commander:*:reset\nalice:unit: one:reset,exclude,reinstate,force\n";
  }
  a.config.permissions_path = a.dir.file("permissions");
  Ground g(a.config);
  ASSERT_TRUE(g.start().ok());
  const auto sign_in = [&](const std::string& user) {
    const Reply r = g.request("POST", "/api/login", kJson, login_body(user, "correct horse"));
    const auto at = r.head.find("tetra_session=");
    return "Cookie: " + r.head.substr(at, r.head.find(';', at) - at) + "\r\n" + kJson +
           "X-CSRF-Token: " + r.data()["csrf"].get<std::string>() + "\r\n";
  };
  const std::string alice = sign_in("alice");
  const std::string bob = sign_in("bob");
  const auto command = [](const std::string& unit, const std::string& action, bool force) {
    return json{{"unit", unit}, {"action", action}, {"gyro", 3}, {"force", force}}.dump();
  };
  const auto reset = [](const std::string& unit) { return json{{"unit", unit}, {"action", "reset"}}.dump(); };
  // bob has the role's lines: reset anywhere, nothing else.
  EXPECT_EQ(g.request("POST", "/api/command", bob, reset("unit: one")).status, 200);
  const Reply no = g.request("POST", "/api/command", bob, command("unit: one", "exclude", false));
  EXPECT_EQ(no.status, 403);
  EXPECT_NE(no.body.find("no permission for exclude on unit 'unit: one' (role commander)"), std::string::npos)
      << no.body;
  // alice has lines of her own: everything on "unit: one" (a colon in its name), nothing elsewhere.
  EXPECT_EQ(g.request("POST", "/api/command", alice, command("unit: one", "exclude", false)).status, 200);
  EXPECT_EQ(g.request("POST", "/api/command", alice, reset("tetra-2")).status, 403);
  // A forced exclusion needs force from the requester and from the approver.
  const Reply held = g.request("POST", "/api/command", alice, command("unit: one", "exclude", true));
  ASSERT_EQ(held.status, 202);
  EXPECT_EQ(g.request("POST", "/api/approve", bob, json{{"id", held.data()["pending"]}}.dump()).status, 403);
  EXPECT_EQ(g.sent.size(), 2U);
  // A line the ground cannot read stops it with the file and line.
  {
    std::ofstream f(a.dir.file("bad"));
    f << "@commander:*:launch\n";
  }
  a.config.permissions_path = a.dir.file("bad");
  Ground bad(a.config);
  const auto s = bad.start();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("bad:1: command 'launch'"), std::string::npos) << s.error().message;
}

TEST(GroundAttacks, AuditRecordsAreJsonLinesThatNoRequestCanForge) {
  Accounts a;
  a.config.audit_path = a.dir.file("audit.jsonl");
  std::ostringstream log;
  const auto previous = spdlog::default_logger();
  auto logger =
      std::make_shared<spdlog::logger>("capture", std::make_shared<spdlog::sinks::ostream_sink_mt>(log));
  spdlog::set_default_logger(logger);
  {
    Ground g(a.config);
    ASSERT_TRUE(g.start().ok());
    const std::string forged = "ground audit: mallory (commander) signed in from 10.0.0.1";
    const Reply alice = g.request("POST", "/api/login", kJson, login_body("alice", "correct horse"));
    ASSERT_EQ(alice.status, 200);
    const auto at = alice.head.find("tetra_session=");
    const std::string cookie = "Cookie: " + alice.head.substr(at, alice.head.find(';', at) - at) + "\r\n";
    const std::string csrf = "X-CSRF-Token: " + alice.data()["csrf"].get<std::string>() + "\r\n";
    // A %0A in the path, a bare LF in Host: refused by the parser, never a line anywhere.
    EXPECT_EQ(g.request("GET", "/x%0A" + std::string("ground%20audit:%20mallory")).status, 400);
    EXPECT_EQ(raw(g, "GET / HTTP/1.1\r\nHost: 127.0.0.1\n" + forged + "\r\n\r\n").status, 400);
    // Newlines and quotes where the JSON body carries them: a user name, a unit, an Origin.
    EXPECT_EQ(g.request("POST", "/api/login", kJson, login_body("x\n" + forged, "p")).status, 401);
    EXPECT_EQ(g.request("POST", "/api/command", cookie + kJson + csrf,
                        json{{"unit", "u\n" + forged + "\"}"}, {"action", "reset"}}.dump())
                  .status,
              200);
    EXPECT_EQ(g.request("GET", "/api/units", "Origin: http://evil\"\\.example\r\n" + cookie).status, 403);
    // A refused cookie is audited.
    EXPECT_EQ(g.request("GET", "/api/units", "Cookie: tetra_session=0123abcd\r\n").status, 401);
    EXPECT_EQ(g.request("POST", "/api/logout", cookie + kJson + csrf, "{}").status, 200);
    EXPECT_EQ(g.request("GET", "/api/units", cookie).status, 401);  // signed out: refused, audited
  }
  spdlog::set_default_logger(previous);
  std::ifstream in(a.config.audit_path);
  std::vector<json> records;
  for (std::string line; std::getline(in, line);) {
    const json r = json::parse(line, nullptr, false);
    ASSERT_TRUE(r.is_object()) << line;
    for (const char* key : {"time_ms", "decision", "outcome", "status", "operator", "address", "method",
                            "path", "unit", "command", "reason"})
      EXPECT_TRUE(r.contains(key)) << key << " in " << line;
    records.push_back(r);
  }
  // In order: sign-in, failed sign-in, command, Origin, a bogus cookie, sign-out, the signed-out cookie.
  ASSERT_EQ(records.size(), 7U);
  EXPECT_EQ(records[0]["decision"], "sign-in");
  EXPECT_EQ(records[0]["outcome"], "accepted");
  EXPECT_EQ(records[1]["status"], 401);
  EXPECT_EQ(records[1]["operator"], "?");  // not a user name: not written
  EXPECT_EQ(records[2]["decision"], "command");
  EXPECT_EQ(records[2]["unit"].get<std::string>().find('\n'), 1U);  // carried, escaped in the file
  EXPECT_EQ(records[2]["decided_by"], "service");
  EXPECT_EQ(records[3]["status"], 403);
  EXPECT_EQ(records[4]["decision"], "session");
  EXPECT_EQ(records[4]["reason"], "session cookie unknown, expired or signed out");
  EXPECT_EQ(records[5]["decision"], "sign-out");
  EXPECT_EQ(records[6]["decision"], "session");
  // Every log line is one of the logger's: none starts with what a client sent.
  std::istringstream lines(log.str());
  int audit_lines = 0;
  for (std::string line; std::getline(lines, line);) {
    EXPECT_EQ(line.rfind("[20", 0), 0U) << line;
    audit_lines += line.find("ground audit:") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(audit_lines, 7);  // the two the parser refused are no decision of the ground's
}

TEST(GroundAttacks, RequestsTwoReadersCouldReadDifferentlyAreRefused) {
  ServerConfig config;
  config.no_auth = true;
  Ground g(config);
  ASSERT_TRUE(g.start().ok());
  const std::string host = "Host: " + g.host() + "\r\n";
  const std::string csrf = g.request("GET", "/api/session").data()["csrf"].get<std::string>();
  const std::string post = "POST /api/command HTTP/1.1\r\n" + host + kJson + "X-CSRF-Token: " + csrf + "\r\n";
  const std::string body = R"({"unit":"u","action":"reset"})";
  for (const std::string& bad : {
           post + "Content-Length : 29\r\n\r\n" + body,                         // a space before the colon
           "GET /api/units HTTP/1.1\n" + host + "\n",                           // bare LF
           "GET /api/units HTTP/1.1\r\n" + host + "X-A: 1\r\n folded\r\n\r\n",  // obs-fold
           post + "Content-Length: 29\r\nContent-Length: 30\r\n\r\n" + body,    // two lengths
           post + "Content-Length: 29, 29\r\n\r\n" + body,                      // a list (Beast takes it)
           "GET /api/units HTTP/1.1\r\n" + host + "X-A: a\rb\r\n\r\n",          // a bare CR
           "GET /api/units  HTTP/1.1\r\n" + host + "\r\n",                      // two spaces
       }) {
    const Reply r = raw(g, bad);
    EXPECT_EQ(r.status, 400) << bad;
    EXPECT_TRUE(r.data().is_object()) << r.body;
  }
  EXPECT_TRUE(g.sent.empty());
  // A body that is a request: one answer, one command.
  const Reply one = raw(
      g, post + "Content-Length: " + std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body);
  EXPECT_EQ(one.status, 200) << one.body;
  EXPECT_EQ(g.sent.size(), 1U);
  // Bytes that are not UTF-8: a 400 with a JSON body, never a 500.
  for (const std::string& bad : {"GET /api/history?unit=%FF%FE&kind=event HTTP/1.1\r\n" + host + "\r\n",
                                 "GET /%C0%AF HTTP/1.1\r\n" + host + "\r\n",
                                 "GET /api/units HTTP/1.1\r\n" + host + "X-Name: \xff\xfe\r\n\r\n"}) {
    const Reply r = raw(g, bad);
    EXPECT_EQ(r.status, 400) << bad;
    EXPECT_TRUE(r.data().is_object()) << r.body;
  }
  const Reply latin1 = raw(g, post + "Content-Length: 30\r\nConnection: close\r\n\r\n" +
                                  "{\"unit\":\"\xe9t\xe9\",\"action\":\"reset\"}");
  EXPECT_EQ(latin1.status, 400) << latin1.body;
  EXPECT_TRUE(latin1.data().is_object()) << latin1.body;
  // HEAD: the head, its length, no body. Other methods: 405 with Allow.
  const Reply head = raw(g, "HEAD /login.html HTTP/1.1\r\n" + host + "Connection: close\r\n\r\n");
  EXPECT_EQ(head.status, 200);
  EXPECT_NE(head.head.find("Content-Length: "), std::string::npos);
  EXPECT_EQ(head.head.find("Content-Length: 0\r"), std::string::npos);
  EXPECT_TRUE(head.body.empty()) << head.body.size();
  const Reply del = raw(g, "DELETE /api/units HTTP/1.1\r\n" + host + "Connection: close\r\n\r\n");
  EXPECT_EQ(del.status, 405);
  EXPECT_NE(del.head.find("Allow: GET, HEAD"), std::string::npos) << del.head;
  const Reply get_command = raw(g, "GET /api/command HTTP/1.1\r\n" + host + "Connection: close\r\n\r\n");
  EXPECT_EQ(get_command.status, 405);
  EXPECT_NE(get_command.head.find("Allow: POST"), std::string::npos) << get_command.head;
  // A request followed by FIN (no Connection: close) is answered.
  const Reply fin = raw(g, "GET /api/session HTTP/1.1\r\n" + host + "\r\n", true);
  EXPECT_EQ(fin.status, 200) << fin.head;
  EXPECT_EQ(fin.data()["user"], "anonymous");
  // A head and its body in two writes 100 ms apart (as Python's and most clients send them), then a
  // second request on the same connection: each answered once, whole.
  const int fd = connect_to(g.port());
  const std::string first = post + "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n";
  (void)::send(fd, first.data(), first.size(), MSG_NOSIGNAL);
  std::this_thread::sleep_for(100ms);
  const std::string rest = body + "GET /api/session HTTP/1.1\r\n" + host + "Connection: close\r\n\r\n";
  (void)::send(fd, rest.data(), rest.size(), MSG_NOSIGNAL);
  const std::string both = read_from(fd);
  ::close(fd);
  EXPECT_EQ(both.rfind("HTTP/1.1 200 OK\r\n", 0), 0U) << both;
  EXPECT_NE(both.find("HTTP/1.1 200 OK\r\n", 10), std::string::npos) << both;
  EXPECT_EQ(g.sent.size(), 2U);
}

TEST(GroundAttacks, ClientsThatDoNotReadAndAddressesThatHoldEveryConnectionAreBounded) {
  ServerConfig config;
  config.no_auth = true;
  config.limits.write_timeout_s = 0.5;
  config.limits.min_write_rate = 1e9;  // the deadline is then 0.5 s for any size
  config.limits.max_connections = 64;
  config.limits.max_connections_per_address = 16;
  Ground g(config);
  ASSERT_TRUE(g.start().ok());
  const std::string get = "GET /login.html HTTP/1.1\r\nHost: " + g.host() + "\r\n\r\n";
  // Requests sent as fast as the socket takes them, never a byte read: the server stops reading (its
  // buffer is bounded), so the sender is stopped too (the kernel's buffers are all it can fill).
  {
    const int fd = connect_to(g.port());
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    std::string batch;
    while (batch.size() < (1U << 20)) batch += get;
    std::size_t sent = 0;
    for (;;) {
      pollfd p{fd, POLLOUT, 0};
      if (::poll(&p, 1, 1000) <= 0 || sent > (256U << 20)) break;
      const ssize_t n = ::send(fd, batch.data(), batch.size(), MSG_NOSIGNAL);
      if (n <= 0) break;
      sent += static_cast<std::size_t>(n);
    }
    EXPECT_LT(sent, 64U << 20) << "bytes the server took from a client that never reads";
    ::close(fd);
  }
  // A reader taking a few bytes now and then: closed at the write deadline, the answer unfinished.
  {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    const int small = 2048;
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(g.port()));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof to), 0);
    const std::string big = "GET /openmct/openmct.js.map HTTP/1.1\r\nHost: " + g.host() + "\r\n\r\n";
    (void)::send(fd, big.data(), big.size(), MSG_NOSIGNAL);  // 12 MiB, more than the kernel buffers
    std::size_t got = 0;
    const auto start = std::chrono::steady_clock::now();
    char buf[64];
    for (;;) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
      if (n == 0 || (n < 0 && errno != EAGAIN)) break;
      if (n > 0) got += static_cast<std::size_t>(n);
      if (std::chrono::steady_clock::now() - start > 20s) break;
      std::this_thread::sleep_for(20ms);
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, 10s) << "the trickling reader was not closed";
    EXPECT_LT(got, 1U << 20);
    ::close(fd);
  }
  // One address opens more connections than the server holds: beyond its share they are closed at
  // once, and an operator on another address is answered.
  std::vector<int> idle;
  for (int i = 0; i < 80; ++i) idle.push_back(connect_to(g.port(), "127.0.0.7"));
  std::this_thread::sleep_for(200ms);
  EXPECT_EQ(g.request("GET", "/api/units", "", "", "127.0.0.8").status, 200);
  for (const int fd : idle) ::close(fd);
}

}  // namespace
}  // namespace tetra::ground
