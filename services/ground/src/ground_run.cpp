// The ground station as one call (tetra/ground/ground_run.hpp).
#include "tetra/ground/ground_run.hpp"

#include <chrono>
#include <cstdint>
#include <stdexcept>

#include "tetra/ground/ground_bridge.hpp"
#include "tetra/ground/ground_readers.hpp"

namespace tetra::ground {

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

Status run_ground(GroundOptions options, dds::ShutdownSignal& shutdown, std::ostream& out) {
  ServerConfig& server_config = options.server;
  if (server_config.no_auth && !server_config.users_path.empty())
    return bad_input("--no-auth and --users: one or the other");
  if (auto s = parse_listen(options.listen, server_config.host, server_config.port); !s) return s;
  if (server_config.no_auth && !is_loopback_host(server_config.host))
    return bad_input("--no-auth: only on a loopback address (--listen 127.0.0.1:PORT)");
  if (!server_config.no_auth && server_config.users_path.empty())
    return bad_input("--users FILE (tetra ground passwd USER --users FILE) or, on loopback only, --no-auth");
  auto readers = GroundReaders::open(options.domain, "", shutdown);
  if (!readers) return readers.error();
  GroundStore store(options.store);
  GroundBridge bridge(std::move(readers).value(), store);
  const auto timeout = std::chrono::milliseconds(static_cast<std::int64_t>(options.command_timeout_s * 1000));
  GroundServer server(
      store, [&](const CommandRequest& request) { return bridge.send(request, timeout); }, server_config);
  if (auto s = server.start(); !s) return s;
  out << "tetra ground: " << (server_config.tls.cert.empty() ? "http" : "https") << "://"
      << server_config.host << ':' << server.port() << "/" << std::endl;
  auto status = bridge.run(shutdown);
  server.stop();
  return status;
}

}  // namespace tetra::ground
