// tetra ground — the ground station in the browser (docs/ground.md): a bridge from DDS (Health,
// FdiEvent, Attitude of every unit) to browsers over HTTP (server-sent events, history, commands as
// JSON POST), and the Open MCT application of web/. Loopback by default; operators sign in with the
// accounts of --users (tetra ground passwd); --no-auth on loopback only.

#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/ground/ground_run.hpp"

namespace tetra::cli {

int cmd_ground(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "passwd") return cmd_ground_passwd(argc - 1, argv + 1);
  dds::ShutdownSignal shutdown;
  CLI::App app{"Ground station in the browser: DDS to HTTP bridge and the Open MCT application.", "ground"};
  ground::GroundOptions o;
  o.server.web_dir = default_web_dir();
  ground::StoreConfig& store_config = o.store;
  ground::ServerConfig& server_config = o.server;
  app.add_option("--listen", o.listen,
                 "HOST:PORT to serve on (default loopback only; port 0: any free port)");
  app.add_option(
         "--web", server_config.web_dir,
         "the web application's directory (with node_modules/ from npm ci); default: ../share/tetra/web "
         "beside the program when installed, else the source tree's web/")
      ->capture_default_str();
  app.add_option("--records", server_config.records_dir,
                 "serve the attitude and event files of tetra record in this folder (/api/records)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--history", store_config.history_s, "[s] history kept per unit")
      ->check(CLI::Range(1.0, 86400.0));
  app.add_option("--attitude-rate", store_config.attitude_rate_hz,
                 "[Hz] attitude rate streamed to browsers and kept in history")
      ->check(CLI::Range(0.1, 100.0));
  app.add_option("--command-timeout", o.command_timeout_s,
                 "[s] wait this long for a command's acknowledgement")
      ->check(CLI::PositiveNumber);
  app.add_option("--users", server_config.users_path,
                 "operator accounts (tetra ground passwd USER --users FILE); required unless --no-auth")
      ->check(CLI::ExistingFile);
  app.add_option("--session-key", server_config.session_key_path,
                 "the key of the session journal and the CSRF tokens (default: the --users file's name + "
                 ".session-key; created when absent, refused when group or others may read it); the sessions "
                 "are kept in the --users file's name + .sessions");
  app.add_option(
         "--permissions", server_config.permissions_path,
         "per-unit and per-command permissions of commanders: WHO:UNIT:COMMANDS lines (docs/ground.md, "
         "Permissions); without it a commander may send every command to every unit")
      ->check(CLI::ExistingFile);
  app.add_option("--audit", server_config.audit_path,
                 "the audit file: one JSON line per sign-in, sign-out, command and refused request (default: "
                 "the --users file's name + .audit.jsonl; none under --no-auth unless given; mode 0600)");
  app.add_option("--max-connections-per-address", server_config.limits.max_connections_per_address,
                 "connections held from one client address (beyond: closed at once; behind a proxy every "
                 "client has the proxy's address)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_flag(
      "--no-auth", server_config.no_auth,
      "no accounts: whoever reaches the port commands as 'anonymous' (loopback addresses only; logged)");
  app.add_option("--allow-origin", server_config.allow_origins,
                 "another HOST:PORT browsers reach this ground as (a DNS name, a proxy); repeatable");
  app.add_option(
      "--trusted-proxy-header", server_config.trusted_proxy_header,
      "sign-in by a reverse proxy: the header naming the user it authenticated (e.g. X-Remote-User; "
      "taken only from --trusted-proxy, the user needs an account in --users; docs/ground.md)");
  app.add_option("--trusted-proxy", server_config.trusted_proxies,
                 "the numeric address the proxy connects from (of --trusted-proxy-header); repeatable");
  app.add_option("--tls-cert", server_config.tls.cert, "PEM certificate (chain): serve HTTPS")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-key", server_config.tls.key, "PEM private key of --tls-cert")
      ->check(CLI::ExistingFile);
  app.add_option("--max-streams", server_config.limits.max_streams,
                 "event streams held at once (beyond: 503)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  add_domain_option(app, o.domain);
  if (auto exit = parse(app, argc, argv)) return *exit;
  if (auto status = ground::run_ground(std::move(o), shutdown, std::cout); !status)
    return report("ground", status.error());
  return kExitOk;
}

}  // namespace tetra::cli
