#include "tetra/ground/http_api.hpp"

#include <arpa/inet.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>

#include "tetra/ground/encode.hpp"
#include "tetra/ground/query_params.hpp"
#include "tetra/ground/record_files.hpp"
#include "tetra/ground/strict_json.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {

namespace {

//! The audit record of an accepted sign-in or sign-out.
AuditRecord accepted_record(const char* decision, const std::string& user, Role role,
                            std::string reason = "") {
  AuditRecord r;
  r.decision = decision;
  r.outcome = "accepted";
  r.status = 200;
  r.operator_id = user;
  r.role = to_string(role);
  r.reason = std::move(reason);
  return r;
}

using nlohmann::json;

constexpr const char* kCookie = "tetra_session";
constexpr std::size_t kMaxCatchUp = 4096;  //!< a resume further behind gets a reset and the history

std::string lower_case(std::string s) {
  for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::int64_t utc_now_s() {
  return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

//! The value of cookie `name` in a Cookie header ("" when absent).
std::string cookie_value(const std::string& header, const std::string& name) {
  std::size_t pos = 0;
  while (pos < header.size()) {
    auto end = header.find(';', pos);
    if (end == std::string::npos) end = header.size();
    std::string item = header.substr(pos, end - pos);
    pos = end + 1;
    const auto b = item.find_first_not_of(' ');
    if (b == std::string::npos) continue;
    item = item.substr(b);
    if (item.compare(0, name.size() + 1, name + "=") == 0) return item.substr(name.size() + 1);
  }
  return "";
}

bool is_json_type(const std::string& content_type) {
  const std::string t = lower_case(content_type.substr(0, content_type.find(';')));
  return t == "application/json";
}

//! "HOST:PORT" of an allow-list entry given as HOST:PORT or SCHEME://HOST:PORT.
std::string host_port_of(std::string text) {
  const auto scheme = text.find("://");
  if (scheme != std::string::npos) text = text.substr(scheme + 3);
  if (!text.empty() && text.back() == '/') text.pop_back();
  return lower_case(text);
}

//! "HOST" without a port (a browser omits the scheme's default) as "HOST:80" or "HOST:443".
std::string with_port(std::string host_port, bool tls) {
  const auto colon = host_port.rfind(':');
  const auto bracket = host_port.rfind(']');
  if (!host_port.empty() && (colon == std::string::npos || (bracket != std::string::npos && colon < bracket)))
    host_port += tls ? ":443" : ":80";
  return host_port;
}

}  // namespace

HttpResponse json_reply(int status, const nlohmann::json& body) {
  HttpResponse res;
  res.status = status;
  res.body = json_text(body);
  res.headers.emplace_back("Cache-Control", "no-store");
  return res;
}

HttpResponse error_reply(int status, const std::string& message) {
  return json_reply(status, {{"error", message}});
}

bool is_loopback_host(const std::string& host) {
  if (host == "localhost" || host == "::1" || host == "[::1]") return true;
  in_addr a{};
  return ::inet_pton(AF_INET, host.c_str(), &a) == 1 && (ntohl(a.s_addr) >> 24U) == 127U;
}

GroundServer::GroundServer(GroundStore& store, SendCommand send, ServerConfig config)
    : store_(store),
      send_(std::move(send)),
      config_(std::move(config)),
      throttle_(config_.throttle),
      approvals_(config_.approval_timeout_s) {}

GroundServer::~GroundServer() {
  stop();
}

Status GroundServer::start() {
  if (config_.no_auth && !is_loopback_host(config_.host))
    return bad_input("--no-auth: only on a loopback address (--listen 127.0.0.1:PORT), not " + config_.host);
  if (!config_.no_auth) {
    if (config_.users_path.empty())
      return bad_input("--users FILE (made by `tetra ground passwd`) or, on loopback only, --no-auth");
    const std::string key =
        config_.session_key_path.empty() ? config_.users_path + ".session-key" : config_.session_key_path;
    auto ops = Operators::open(config_.users_path, key, config_.users_path + ".sessions", utc_now_s());
    if (!ops) return ops.error();
    operators_.emplace(std::move(ops).value());
  }
  auto proxy = TrustedProxy::make(config_.trusted_proxy_header, config_.trusted_proxies);
  if (!proxy) return proxy.error();
  if (proxy->enabled() && config_.no_auth)
    return bad_input(
        "--trusted-proxy-header: the proxy names operators of the --users file, not with --no-auth");
  proxy_ = std::move(proxy).value();
  const std::string audit_path = !config_.audit_path.empty() || config_.no_auth
                                     ? config_.audit_path
                                     : config_.users_path + ".audit.jsonl";
  if (!config_.permissions_path.empty()) {
    auto permissions = Permissions::read(config_.permissions_path);
    if (!permissions) return permissions.error();
    permissions_ = std::move(permissions).value();
  }
  auto audit = AuditLog::open(audit_path);
  if (!audit) return audit.error();
  audit_ = std::move(audit).value();
  if (config_.tls.cert.empty() != config_.tls.key.empty())
    return bad_input("--tls-cert and --tls-key go together");
  if (!files_.mount("/", config_.web_dir))
    return bad_input("--web " + config_.web_dir + ": no such directory");
  const std::filesystem::path openmct = std::filesystem::path(config_.web_dir) / "node_modules/openmct/dist";
  if (!files_.mount("/openmct/", openmct.string()))
    return failure(openmct.string() + " missing: run `bash scripts/setup.sh --web` (npm ci in " +
                   config_.web_dir + "; the other commands do not need it)");
  instance_ = random_hex(4);
  no_auth_csrf_ = random_hex(32);
  StreamFeed feed{[this](std::uint64_t after, std::string& out) { return feed_next(after, out); },
                  [this] { return store_.last_id(); }};
  // Sign-ins take a password check each (64 MiB, about 0.3 s): on the server's slow lane, their own
  // workers and queue, so they never hold up the rest of the API or each other beyond that queue.
  server_ = std::make_unique<HttpServer>(
      [this](const HttpRequest& r) { return handle(r); }, std::move(feed), config_.limits,
      [](const HttpRequest& r) { return r.method == "POST" && r.path == "/api/login"; });
  if (auto s = server_->start(config_.host, config_.port, config_.tls); !s) return s;
  const std::string port = ":" + std::to_string(server_->port());
  for (const std::string& h :
       {config_.host, std::string("localhost"), std::string("127.0.0.1"), std::string("[::1]")})
    allowed_hosts_.insert(lower_case(h.find(':') != std::string::npos && h[0] != '[' ? "[" + h + "]" : h) +
                          port);
  for (const auto& extra : config_.allow_origins)
    allowed_hosts_.insert(with_port(host_port_of(extra), !config_.tls.cert.empty()));
  store_.set_listener([server = server_.get()] { server->notify(); });
  if (config_.no_auth)
    spdlog::warn("ground: --no-auth: no accounts; whoever reaches {}{} may command (as 'anonymous')",
                 config_.host, port);
  return ok_status();
}

void GroundServer::stop() {
  store_.set_listener(nullptr);
  if (server_) server_->stop();
}

void GroundServer::append_message(std::string& out, const StreamMessage& m) const {
  if (m.id != 0) out += "id: " + instance_ + "-" + std::to_string(m.id) + '\n';
  out += "event: " + m.event + "\ndata: " + m.data + "\n\n";
}

std::uint64_t GroundServer::feed_next(std::uint64_t after, std::string& out) const {
  const StreamRead read = store_.read_stream(after, 512, std::chrono::milliseconds(0));
  if (read.gap) out += "event: reset\ndata: {}\n\n";
  for (const auto& m : read.messages) {
    append_message(out, m);
    after = m.id;
  }
  return after;
}

void GroundServer::audit(const HttpRequest& req, AuditRecord record) {
  record.address = req.remote_addr;
  record.method = req.method;
  record.path = req.path;
  audit_.write(record);
}

HttpResponse GroundServer::refuse(const HttpRequest& req, int status, const std::string& why,
                                  const std::string& user, const std::string& role) {
  AuditRecord r;
  r.decision = req.path == "/api/login" ? "sign-in" : (req.path == "/api/command" ? "command" : "request");
  r.outcome = "refused";
  r.status = status;
  r.operator_id = user;
  r.role = role;
  r.reason = why;
  audit(req, std::move(r));
  return error_reply(status, why);
}

std::optional<Session> GroundServer::session_of(const HttpRequest& req) {
  if (config_.no_auth) return Session{"anonymous", Role::kCommander, no_auth_csrf_};
  const std::string token = cookie_value(req.header("cookie"), kCookie);
  if (token.empty()) return std::nullopt;
  auto session = operators_->session(token, utc_now_s());
  if (!session) {
    AuditRecord r;
    r.decision = "session";
    r.outcome = "refused";
    r.status = req.path.rfind("/api/", 0) == 0 ? 401 : 302;
    r.reason = "session cookie unknown, expired or signed out";
    audit(req, std::move(r));
  }
  return session;
}

std::optional<Result<Session>> GroundServer::proxied_session(const HttpRequest& req) {
  if (!proxy_.enabled() || req.headers.count(proxy_.header()) == 0) return std::nullopt;
  const std::string user = req.header(proxy_.header());
  if (!proxy_.trusts(req.remote_addr))
    return Result<Session>(bad_input("header " + config_.trusted_proxy_header + " from " + req.remote_addr +
                                     ", not a --trusted-proxy address"));
  if (user.empty()) return std::nullopt;  // the proxy signed nobody in: the ground's own sign-in
  auto session = valid_user_name(user) ? operators_->by_proxy(user) : std::nullopt;
  if (!session)
    return Result<Session>(bad_input("the proxy's user '" + user + "' has no account in the --users file"));
  bool first = false;
  {
    const std::lock_guard lock(proxied_mutex_);
    first = proxied_seen_.insert(user).second;
  }
  if (first) {  // audited once a run, as a sign-in; every command is audited with the operator anyway
    audit(req, accepted_record("sign-in", session->user, session->role,
                               "authenticated by the proxy at " + req.remote_addr + " (" +
                                   config_.trusted_proxy_header + ")"));
  }
  return Result<Session>(std::move(*session));
}

bool GroundServer::browser_tls(const HttpRequest& req) const {
  // Behind the trusted proxy, its X-Forwarded-Proto tells whether the browser's side is HTTPS.
  return req.tls || (proxy_.enabled() && proxy_.trusts(req.remote_addr) &&
                     lower_case(req.header("x-forwarded-proto")) == "https");
}

HttpResponse GroundServer::handle(const HttpRequest& req) {
  const bool tls = browser_tls(req);
  // DNS rebinding: a name that resolves to this host is not enough, the browser must call it by a name
  // of the allow-list. A cross-site page: its Origin is not on the list.
  const std::string host = with_port(lower_case(req.header("host")), tls);
  if (allowed_hosts_.count(host) == 0)
    return refuse(req, 403, "Host '" + host + "' not allowed (--allow-origin adds one)", "");
  const std::string origin = req.header("origin");
  if (!origin.empty()) {
    const std::string scheme = tls ? "https://" : "http://";
    if (origin.compare(0, scheme.size(), scheme) != 0 ||
        allowed_hosts_.count(with_port(host_port_of(origin), tls)) == 0)
      return refuse(req, 403, "Origin '" + origin + "' not allowed", "");
  }
  // POST for what changes something, GET (or HEAD: the same head, no body) for the rest.
  const bool post_only = req.path == "/api/login" || req.path == "/api/logout" ||
                         req.path == "/api/command" || req.path == "/api/approve";
  const bool get = req.method == "GET" || req.method == "HEAD";
  if (post_only ? req.method != "POST" : !get) {
    auto res = refuse(req, 405, std::string(post_only ? "POST" : "GET or HEAD") + " only here", "");
    res.headers.emplace_back("Allow", post_only ? "POST" : "GET, HEAD");
    return res;
  }
  if (req.method == "POST" && !is_json_type(req.header("content-type")))
    return refuse(req, 415, "a POST must be application/json", "");
  if (req.path == "/api/login") return login(req);
  if (get && (req.path == "/login.html" || req.path == "/login.js" || req.path == "/tetra.css"))
    return serve(req, std::nullopt);
  auto proxied = proxied_session(req);
  if (proxied && !*proxied) return refuse(req, 403, proxied->error().message, "");
  const auto session = proxied ? std::optional<Session>(std::move(**proxied)) : session_of(req);
  if (!session) {
    if (req.path.rfind("/api/", 0) == 0) return error_reply(401, "sign in first (/login.html)");
    HttpResponse res;
    res.status = 302;
    res.content_type = "text/plain";
    res.headers.emplace_back("Location", "/login.html");
    return res;
  }
  if (req.method == "POST" && !same_secret(req.header("x-csrf-token"), session->csrf))
    return refuse(req, 403, "the session's CSRF token is missing or wrong (X-CSRF-Token)", session->user,
                  to_string(session->role));
  return serve(req, session);
}

HttpResponse GroundServer::serve(const HttpRequest& req, const std::optional<Session>& session) {
  if (req.method == "POST") {
    if (req.path == "/api/command") return command(req, *session);
    if (req.path == "/api/approve") return approve(req, *session);
    return logout(req, *session);
  }
  const auto now = steady_now_ns();
  if (req.path == "/api/session") {
    return json_reply(200, {{"user", session->user},
                            {"role", to_string(session->role)},
                            {"csrf", session->csrf},
                            {"auth", !config_.no_auth},
                            {"by_proxy", session->by_proxy}});
  }
  if (req.path == "/api/units") {
    if (!req.params.empty()) return error_reply(400, "parameter '" + req.params[0].first + "' unknown here");
    return json_reply(200, store_.units_json(now));
  }
  if (req.path == "/api/status") {
    return json_reply(200, {{"last_event_id", instance_ + "-" + std::to_string(store_.last_id())},
                            {"stream_dropped", store_.stream_dropped()},
                            {"streams", server_->open_streams()},
                            {"units", store_.units_json(now)}});
  }
  if (req.path == "/api/pending") return json_reply(200, approvals_.list(now));
  if (req.path == "/api/history") return history(req);
  if (req.path == "/api/records") return records(req);
  if (req.path == "/api/stream") return stream(req);
  if (req.path.rfind("/api/", 0) == 0) return error_reply(404, "no such request");
  const auto file = files_.get(req.path);
  if (!file) return error_reply(404, "no such file");
  HttpResponse res;
  res.content_type = file->content_type;
  res.shared_body = file->content;
  return res;
}

HttpResponse GroundServer::login(const HttpRequest& req) {
  if (config_.no_auth) return error_reply(404, "--no-auth: no accounts to sign in to");
  auto body = parse_strict_json(req.body);
  if (!body || !body->is_object() || !(*body)["user"].is_string() || !(*body)["password"].is_string() ||
      body->size() != 2)
    return error_reply(400, "login: a JSON object {\"user\", \"password\"}");
  const std::string user = (*body)["user"].get<std::string>();
  const std::string shown = valid_user_name(user) ? user : "?";
  // Refused before the password is checked: costs no hash and is not counted as a failure.
  const std::int64_t at = steady_now_ns();
  // Failures are counted by the name as written when it is a valid user name, else under "?" (no
  // account has it): a flood of long made-up names takes no memory.
  const auto verdict = throttle_.admit(shown, req.remote_addr, at);
  if (!verdict.allowed) {
    // The 1st, 2nd, 4th, 8th... refusal since the last check is recorded, the others only answered.
    const std::uint64_t n = verdict.refused_before + 1;
    auto res =
        (n & (n - 1)) != 0
            ? error_reply(429, verdict.reason)
            : refuse(req, 429, verdict.reason + " (refusal " + std::to_string(n) + " since the last check)",
                     shown);
    res.headers.emplace_back("Retry-After",
                             std::to_string(static_cast<long>(std::ceil(verdict.retry_after_s))));
    return res;
  }
  const auto account = operators_->login(user, (*body)["password"].get<std::string>());
  throttle_.record(shown, req.remote_addr, account.has_value(), at);
  if (!account) return refuse(req, 401, "user or password wrong", shown);
  const auto lifetime = static_cast<std::int64_t>(config_.session_lifetime_s);
  const auto issued = operators_->issue(account->user, utc_now_s(), lifetime);
  if (!issued) {
    spdlog::error("ground: {}", issued.error().message);
    return error_reply(500, "the session cannot be recorded");
  }
  const std::string& token = *issued;
  audit(req, accepted_record("sign-in", account->user, account->role));
  auto res = json_reply(
      200, {{"user", account->user}, {"role", to_string(account->role)}, {"csrf", operators_->csrf(token)}});
  res.headers.emplace_back(
      "Set-Cookie", std::string(kCookie) + "=" + token + "; Path=/; Max-Age=" + std::to_string(lifetime) +
                        "; HttpOnly; SameSite=Strict" + (browser_tls(req) ? "; Secure" : ""));
  return res;
}

HttpResponse GroundServer::logout(const HttpRequest& req, const Session& session) {
  if (operators_ && !session.by_proxy) {  // by the proxy: signed out at the proxy
    if (auto s = operators_->revoke(cookie_value(req.header("cookie"), kCookie)); !s)
      return error_reply(500, "sign-out not recorded: " + s.error().message);
  }
  audit(req, accepted_record("sign-out", session.user, session.role));
  auto res = json_reply(200, {{"signed_out", session.user}});
  res.headers.emplace_back("Set-Cookie",
                           std::string(kCookie) + "=; Path=/; Max-Age=0; HttpOnly; SameSite=Strict");
  return res;
}

HttpResponse GroundServer::stream(const HttpRequest& req) {
  auto q = QueryParams::of(req.params, {"last_event_id"});
  if (!q) return error_reply(400, q.error().message);
  std::string last = req.header("last-event-id");
  if (last.empty()) last = q->text("last_event_id");
  HttpResponse res;
  res.stream = true;
  res.stream_start = "retry: 1000\n\n";
  const std::uint64_t newest = store_.last_id();
  // Resume only an id of this run that the ring still holds; anything else (an id of an earlier run of
  // the ground station, one from the future, too far behind) gets a reset and the current state.
  std::uint64_t after = 0;
  bool resume = false;
  const std::string prefix = instance_ + "-";
  if (last.compare(0, prefix.size(), prefix) == 0 && last.size() > prefix.size() &&
      last.size() < prefix.size() + 20 &&
      last.find_first_not_of("0123456789", prefix.size()) == std::string::npos) {
    after = std::stoull(last.substr(prefix.size()));
    resume = after <= newest && newest - after <= kMaxCatchUp &&
             !store_.read_stream(after, 1, std::chrono::milliseconds(0)).gap;
  }
  if (!resume) {
    if (!last.empty()) res.stream_start += "event: reset\ndata: {}\n\n";
    after = newest;
    for (const auto& m : store_.snapshot(steady_now_ns())) append_message(res.stream_start, m);
  }
  res.stream_after = after;
  return res;
}

HttpResponse GroundServer::history(const HttpRequest& req) {
  auto q = QueryParams::of(req.params, {"unit", "unit_id", "kind", "start", "end", "max"});
  if (!q) return error_reply(400, q.error().message);
  const auto start = q->number("start", 0);
  const auto end = q->number("end", 1e300);
  const auto max = q->count("max", 5000, 1, 100000);
  for (const Error* e :
       {start ? nullptr : &start.error(), end ? nullptr : &end.error(), max ? nullptr : &max.error()}) {
    if (e != nullptr) return error_reply(400, e->message);
  }
  const auto unit = requested_unit(q->given("unit"), q->given("unit_id"), "parameter");
  if (!unit) return error_reply(400, unit.error().message);
  auto h = store_.history(*unit, q->text("kind"), *start, *end, *max);
  if (!h) return error_reply(h.error().message.rfind("history kind", 0) == 0 ? 400 : 404, h.error().message);
  return json_reply(200, *h);
}

HttpResponse GroundServer::records(const HttpRequest& req) {
  if (config_.records_dir.empty()) return error_reply(404, "no --records folder given");
  auto q = QueryParams::of(req.params, {"file", "start", "end", "max"});
  if (!q) return error_reply(400, q.error().message);
  if (!q->has("file")) {
    auto list = list_records(config_.records_dir);
    if (!list) return error_reply(500, "the records folder cannot be read");
    return json_reply(200, *list);
  }
  const auto start = q->number("start", -1e300);
  const auto end = q->number("end", 1e300);
  const auto max = q->count("max", 5000, 1, 100000);
  for (const Error* e :
       {start ? nullptr : &start.error(), end ? nullptr : &end.error(), max ? nullptr : &max.error()}) {
    if (e != nullptr) return error_reply(400, e->message);
  }
  auto r = read_record(config_.records_dir, q->text("file"), *start, *end, *max);
  if (!r) return error_reply(404, r.error().message);
  return json_reply(200, *r);
}

}  // namespace tetra::ground
