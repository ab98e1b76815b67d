#pragma once
// The ground station's HTTP interface (docs/ground.md): sign-in and sessions, the web application's
// files, the event stream (server-sent events), history, the units' link states, and commands as JSON
// POST answered with the service's acknowledgement. Every request is checked before it is served:
// its Host and Origin against an allow-list, a session (or the explicit --no-auth of loopback), and for
// a state-changing request the JSON content type, the session's CSRF token and, for a command, the
// commander role. Refusals are logged as audit lines.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/ground/approvals.hpp"
#include "tetra/ground/audit_log.hpp"
#include "tetra/ground/command_request.hpp"
#include "tetra/ground/http_server.hpp"
#include "tetra/ground/login_throttle.hpp"
#include "tetra/ground/operators.hpp"
#include "tetra/ground/permissions.hpp"
#include "tetra/ground/static_files.hpp"
#include "tetra/ground/store.hpp"
#include "tetra/ground/trusted_proxy.hpp"

namespace tetra::ground {

//! Sends a command and waits for its acknowledgement (an error when none comes in time).
using SendCommand = std::function<Result<dds::EventView>(const CommandRequest&)>;

struct ServerConfig {
  std::string host = "127.0.0.1";
  int port = 8080;               //!< 0: any free port (see GroundServer::port())
  std::string web_dir;           //!< the web application (index.html, tetra-plugin.js, node_modules/openmct)
  std::string records_dir;       //!< `tetra record` files served by /api/records ("": none)
  std::string users_path;        //!< operator accounts (tetra ground passwd); "" only with no_auth
  std::string session_key_path;  //!< the key sessions are signed with (created when absent)
  //! The audit file ("": the --users file's name + .audit.jsonl; none under no_auth).
  std::string audit_path;
  std::string permissions_path;  //!< per-unit and per-command permissions of commanders ("": none)
  bool no_auth = false;          //!< no accounts: everyone who reaches the port is commander "anonymous"
  std::vector<std::string> allow_origins;  //!< more HOST:PORT a browser may reach the ground as
  //! Sign-in by a reverse proxy: the header naming the operator it authenticated ("": off), taken only
  //! from these addresses (docs/ground.md, "Sign-in by the proxy").
  std::string trusted_proxy_header;
  std::vector<std::string> trusted_proxies;
  TlsFiles tls;
  HttpLimits limits;
  ThrottleLimits throttle;                  //!< sign-in back-off and lockout
  double session_lifetime_s = 12 * 3600.0;  //!< [s]
  int commands_in_flight = 2;         //!< commands waiting for their acknowledgement at once; beyond: 503
  double approval_timeout_s = 120.0;  //!< [s] a forced exclusion waits this long for a second commander
};

//! A JSON answer (not cached); an error's is {"error": message}.
HttpResponse json_reply(int status, const nlohmann::json& body);
HttpResponse error_reply(int status, const std::string& message);

//! True for 127.0.0.0/8, ::1 and "localhost".
bool is_loopback_host(const std::string& host);

class GroundServer {
 public:
  GroundServer(GroundStore& store, SendCommand send, ServerConfig config);
  ~GroundServer();
  GroundServer(const GroundServer&) = delete;
  GroundServer& operator=(const GroundServer&) = delete;

  //! Checks the configuration, binds and starts serving on threads of its own.
  Status start();
  void stop();
  int port() const { return server_ ? server_->port() : 0; }

 private:
  HttpResponse handle(const HttpRequest& req);
  HttpResponse serve(const HttpRequest& req, const std::optional<Session>& session);
  HttpResponse refuse(const HttpRequest& req, int status, const std::string& why, const std::string& user,
                      const std::string& role = "");
  void audit(const HttpRequest& req, AuditRecord record);
  HttpResponse login(const HttpRequest& req);
  HttpResponse logout(const HttpRequest& req, const Session& session);
  HttpResponse command(const HttpRequest& req, const Session& session);
  HttpResponse approve(const HttpRequest& req, const Session& session);
  //! Sends the command (bounded in flight), audits the answer; `approved_by` a second operator or "".
  HttpResponse send_command(const HttpRequest& req, const CommandRequest& request, const std::string& role,
                            const std::string& approved_by);
  HttpResponse stream(const HttpRequest& req);
  HttpResponse history(const HttpRequest& req);
  HttpResponse records(const HttpRequest& req);
  std::optional<Session> session_of(const HttpRequest& req);
  //! True when the browser reached the ground over HTTPS: its own TLS, or the trusted proxy's.
  bool browser_tls(const HttpRequest& req) const;
  //! The operator the trusted proxy's header names; nullopt without the header; an error (the reason of
  //! a 403) when it comes from another address or names no account.
  std::optional<Result<Session>> proxied_session(const HttpRequest& req);
  std::uint64_t feed_next(std::uint64_t after, std::string& out) const;
  void append_message(std::string& out, const StreamMessage& m) const;

  GroundStore& store_;
  SendCommand send_;
  ServerConfig config_;
  std::unique_ptr<HttpServer> server_;
  std::optional<Operators> operators_;
  StaticFiles files_;
  std::set<std::string> allowed_hosts_;  //!< "host:port", lower case
  std::string instance_;                 //!< this run's prefix of every event id
  std::string no_auth_csrf_;
  AuditLog audit_;
  LoginThrottle throttle_;
  Approvals approvals_;
  Permissions permissions_;
  TrustedProxy proxy_;
  std::mutex proxied_mutex_;
  std::set<std::string> proxied_seen_;  //!< operators the proxy named in this run (their first audited)
  std::atomic<int> commands_waiting_{0};
};

}  // namespace tetra::ground
