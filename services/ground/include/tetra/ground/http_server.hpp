#pragma once
// The ground station's HTTP/1.1 server, built to stay up under abuse (docs/ground.md, threat model), on
// Boost.Beast and Asio (OpenSSL for TLS, 1.2 and later): one I/O thread runs every socket, so a slow or
// silent client holds no thread; a request must arrive whole within a deadline and within size limits
// (Beast's parser and the strict checks of http_parse.hpp), a response be written within its own (Beast's
// per-operation timeouts); a client that does not read is not read either; connections are bounded in
// all and per address; handlers run on a small pool of workers, slow ones (sign-ins) on a pool of their
// own; event streams (server-sent events) are fed by the I/O thread from one shared cursor, each with a
// bounded buffer, and their number is bounded. Inside: http_server_impl.hpp, http_connection.hpp.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/ground/http_parse.hpp"

namespace tetra::ground {

struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::shared_ptr<const std::string> shared_body;  //!< instead of body (cached files)
  std::vector<std::pair<std::string, std::string>> headers;
  //! Turn the connection into an event stream (status 200): `stream_start` is sent first, then every
  //! message the server's StreamFeed yields after `stream_after`.
  bool stream = false;
  std::string stream_start;
  std::uint64_t stream_after = 0;
};

//! Where event streams come from: `next` appends the messages after `after` (as SSE text) and returns
//! the id of the last one appended (`after` when none); `last` is the newest id.
struct StreamFeed {
  std::function<std::uint64_t(std::uint64_t after, std::string& out)> next;
  std::function<std::uint64_t()> last;
};

struct HttpLimits {
  std::size_t max_connections = 4096;              //!< beyond: accepted and closed at once
  std::size_t max_connections_per_address = 2048;  //!< from one client address; beyond: closed at once
  std::size_t max_streams = 1024;                  //!< event streams held; beyond: 503 (logged)
  std::size_t max_head_bytes = 16384;              //!< request line and headers; beyond: 431
  std::size_t max_body_bytes = 65536;              //!< request body; beyond: 413
  std::size_t stream_buffer_bytes = 256U << 10;  //!< per stream not yet written; beyond: the stream is closed
  std::size_t max_queued = 256;                  //!< requests waiting for a worker; beyond: 503
  int workers = 4;                               //!< handler threads
  int slow_workers = 2;                  //!< threads of the slow lane (sign-ins: a password hash each)
  std::size_t max_slow_queued = 32;      //!< slow requests waiting or running; beyond: 503
  std::size_t max_slow_per_address = 2;  //!< slow requests of one address waiting or running; beyond: 429
  double request_timeout_s = 10.0;       //!< [s] a request must arrive whole within this
  double idle_timeout_s = 30.0;          //!< [s] a kept-alive connection with no request is closed
  double write_timeout_s = 10.0;         //!< [s] a response (or a stream) making no progress is closed
  //! [B/s] a response must be written whole within write_timeout_s + its size at this rate (a client
  //! reading a byte now and then is closed); a stream whose buffer has not emptied for write_timeout_s too
  double min_write_rate = 16384.0;
  double keepalive_s = 1.0;  //!< [s] a comment line on a quiet stream at least this often
};

struct TlsFiles {
  std::string cert;  //!< PEM certificate (chain); "" for plain HTTP
  std::string key;   //!< PEM private key
};

class HttpServer {
 public:
  using Handler = std::function<HttpResponse(const HttpRequest&)>;
  //! True for a request that runs on the slow lane (its own workers and bounds: a slow request never
  //! delays the others); called on the I/O thread, so it must be quick.
  using SlowLane = std::function<bool(const HttpRequest&)>;
  HttpServer(Handler handler, StreamFeed feed, HttpLimits limits, SlowLane slow = {});
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  //! Binds (port 0: any free port), loads the TLS files when given, starts the threads.
  Status start(const std::string& host, int port, const TlsFiles& tls);
  void stop();
  int port() const { return port_; }
  //! Wakes the I/O thread: new stream messages (callable from any thread, cheap).
  void notify();
  std::size_t open_streams() const { return streams_; }

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
  std::atomic<std::size_t> streams_{0};
};

}  // namespace tetra::ground
