#pragma once
// The ground station's HTTP server (docs/ground.md): the web application's files, the event stream
// (server-sent events), history, the units' link states, and commands as JSON POST answered with the
// service's acknowledgement. One thread per connection from a bounded pool.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "tetra/core/result.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/ground/command_request.hpp"
#include "tetra/ground/store.hpp"

namespace httplib {
class Server;
}

namespace tetra::ground {

//! Sends a command and waits for its acknowledgement (an error when none comes in time).
using SendCommand = std::function<Result<dds::EventView>(const CommandRequest&)>;

struct ServerConfig {
  std::string host = "127.0.0.1";
  int port = 8080;            //!< 0: any free port (see GroundServer::port())
  std::string web_dir;        //!< the web application (index.html, tetra-plugin.js, node_modules/openmct)
  std::string records_dir;    //!< `tetra record` files served by /api/records ("": none)
  int worker_threads = 32;    //!< concurrent connections (each browser holds one for its stream)
  int stream_wait_ms = 1000;  //!< [ms] a keep-alive comment at least this often on a quiet stream
};

class GroundServer {
 public:
  GroundServer(GroundStore& store, SendCommand send, ServerConfig config);
  ~GroundServer();
  GroundServer(const GroundServer&) = delete;
  GroundServer& operator=(const GroundServer&) = delete;

  //! Binds and starts serving on a thread of its own.
  Status start();
  //! Stops serving; open streams end within stream_wait_ms.
  void stop();
  int port() const { return port_; }

 private:
  void routes();
  GroundStore& store_;
  SendCommand send_;
  ServerConfig config_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  int port_ = 0;
};

}  // namespace tetra::ground
