// tetra ground — the ground station in the browser (docs/ground.md): a bridge from DDS (Health,
// FdiEvent, Attitude of every unit) to browsers over HTTP (server-sent events, history, commands as
// JSON POST), and the Open MCT application of web/. Loopback by default.

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
  add_domain_option(app, domain);
  if (auto exit = parse(app, argc, argv)) return *exit;

  server_config.web_dir = web_dir;
  if (auto s = parse_listen(listen, server_config.host, server_config.port); !s)
    return report("ground", s.error());
  auto readers = ground::GroundReaders::open(domain, "", shutdown);
  if (!readers) return report("ground", readers.error());
  ground::GroundStore store(store_config);
  ground::GroundBridge bridge(std::move(readers).value(), store);
  const auto timeout = std::chrono::milliseconds(static_cast<std::int64_t>(command_timeout_s * 1000));
  ground::GroundServer server(
      store, [&](const ground::CommandRequest& request) { return bridge.send(request, timeout); },
      server_config);
  if (auto s = server.start(); !s) return report("ground", s.error());
  std::cout << "tetra ground: http://" << server_config.host << ':' << server.port() << "/" << std::endl;
  auto status = bridge.run(shutdown);
  server.stop();
  if (!status) return report("ground", status.error());
  return kExitOk;
}

}  // namespace tetra::cli
