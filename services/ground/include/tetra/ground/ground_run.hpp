#pragma once
// The ground station as one call (`tetra ground`, docs/ground.md): the DDS readers, the store, the bridge
// and the HTTP server wired together, serving until a shutdown is requested.

#include <ostream>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/ground/http_api.hpp"
#include "tetra/ground/store.hpp"

namespace tetra::ground {

struct GroundOptions {
  std::string listen = "127.0.0.1:8080";       //!< HOST:PORT served (port 0: any free port)
  StoreConfig store;                           //!< history kept, attitude rate
  ServerConfig server;                         //!< host and port: from `listen`
  double command_timeout_s = 5.0;              //!< [s] wait this long for a command's acknowledgement
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;  //!< the DDS domain read and commanded
};

//! "HOST:PORT" -> host and port (port 0: any free port); a bad-input error naming --listen.
Status parse_listen(const std::string& text, std::string& host, int& port);

//! Checks the options (accounts or --no-auth on loopback), opens the readers and serves; prints the URL on
//! `out` once serving (flushed); returns when `shutdown` is requested.
Status run_ground(GroundOptions options, dds::ShutdownSignal& shutdown, std::ostream& out);

}  // namespace tetra::ground
