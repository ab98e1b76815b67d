// tetra ground — the ground station in the browser (docs/ground.md): a bridge from DDS (Health,
// FdiEvent, Attitude of every unit) to browsers over HTTP (server-sent events, history, commands as
// JSON POST), and the Open MCT application of web/. Loopback by default; operators sign in with the
// accounts of --users (tetra ground passwd); --no-auth on loopback only.

#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/ground/ground_bridge.hpp"
#include "tetra/ground/http_api.hpp"

namespace tetra::cli {

namespace {

//! "HOST:PORT" -> host and port (port 0: any free port).
Status parse_listen(const std::string& text, std::string& host, int& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0)
    return bad_input("--listen '" + text + "': expected HOST:PORT");
  host = text.substr(0, colon);
  try {
    std::size_t used = 0;
    port = std::stoi(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1 || port < 0 || port > 65535) throw std::out_of_range("port");
  } catch (const std::exception&) {
    return bad_input("--listen '" + text + "': the port must be 0..65535");
  }
  return ok_status();
}

}  // namespace

int cmd_ground(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "passwd") return cmd_ground_passwd(argc - 1, argv + 1);
  dds::ShutdownSignal shutdown;
  CLI::App app{"Ground station in the browser: DDS to HTTP bridge and the Open MCT application.", "ground"};
  std::string listen = "127.0.0.1:8080";
  std::string web_dir = default_web_dir();
  ground::StoreConfig store_config;
  ground::ServerConfig server_config;
  double command_timeout_s = 5.0;
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  app.add_option("--listen", listen, "HOST:PORT to serve on (default loopback only; port 0: any free port)");
  app.add_option(
         "--web", web_dir,
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
  app.add_option("--command-timeout", command_timeout_s, "[s] wait this long for a command's acknowledgement")
      ->check(CLI::PositiveNumber);
  app.add_option("--users", server_config.users_path,
                 "operator accounts (tetra ground passwd USER --users FILE); required unless --no-auth")
      ->check(CLI::ExistingFile);
  app.add_option("--session-key", server_config.session_key_path,
                 "the key sessions are signed with (default: the --users file's name + .session-key; created "
                 "when absent)");
  app.add_flag(
      "--no-auth", server_config.no_auth,
      "no accounts: whoever reaches the port commands as 'anonymous' (loopback addresses only; logged)");
  app.add_option("--allow-origin", server_config.allow_origins,
                 "another HOST:PORT browsers reach this ground as (a DNS name, a proxy); repeatable");
  app.add_option("--tls-cert", server_config.tls.cert, "PEM certificate (chain): serve HTTPS")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-key", server_config.tls.key, "PEM private key of --tls-cert")
      ->check(CLI::ExistingFile);
  app.add_option("--max-streams", server_config.limits.max_streams,
                 "event streams held at once (beyond: 503)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  add_domain_option(app, domain);
  if (auto exit = parse(app, argc, argv)) return *exit;
  if (server_config.no_auth && !server_config.users_path.empty())
    return report("ground", bad_input("--no-auth and --users: one or the other"));

  server_config.web_dir = web_dir;
  if (auto s = parse_listen(listen, server_config.host, server_config.port); !s)
    return report("ground", s.error());
  if (server_config.no_auth && !ground::is_loopback_host(server_config.host))
    return report("ground", bad_input("--no-auth: only on a loopback address (--listen 127.0.0.1:PORT)"));
  if (!server_config.no_auth && server_config.users_path.empty())
    return report("ground", bad_input("--users FILE (tetra ground passwd USER --users FILE) or, on loopback "
                                      "only, --no-auth"));
  auto readers = ground::GroundReaders::open(domain, "", shutdown);
  if (!readers) return report("ground", readers.error());
  ground::GroundStore store(store_config);
  ground::GroundBridge bridge(std::move(readers).value(), store);
  const auto timeout = std::chrono::milliseconds(static_cast<std::int64_t>(command_timeout_s * 1000));
  ground::GroundServer server(
      store, [&](const ground::CommandRequest& request) { return bridge.send(request, timeout); },
      server_config);
  if (auto s = server.start(); !s) return report("ground", s.error());
  std::cout << "tetra ground: " << (server_config.tls.cert.empty() ? "http" : "https") << "://"
            << server_config.host << ':' << server.port() << "/" << std::endl;
  auto status = bridge.run(shutdown);
  server.stop();
  if (!status) return report("ground", status.error());
  return kExitOk;
}

}  // namespace tetra::cli
