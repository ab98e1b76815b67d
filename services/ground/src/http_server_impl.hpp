#pragma once
// The inside of the ground's HTTP server (http_server.hpp) on Boost.Beast and Asio: one I/O thread runs
// the io_context (accepting, reading, writing, every deadline), handlers run on two small thread pools
// (the slow lane for sign-ins), event streams are fed from one shared cursor. Shared by
// http_server.cpp (the server) and http_connection.hpp (a connection, plain or TLS).

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>

#include "tetra/ground/http_server.hpp"

namespace tetra::ground::http_detail {

namespace net = boost::asio;

//! An event stream's connection as the broadcaster sees it.
class StreamSink {
 public:
  virtual ~StreamSink() = default;
  //! Appends a batch of messages (shared by every stream); a stream too far behind is closed.
  virtual void push(const std::shared_ptr<const std::string>& chunk) = 0;
};

std::int64_t now_ns();

//! A steady_timer duration of `s` seconds.
inline std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace tetra::ground::http_detail

namespace tetra::ground {

struct HttpServer::Impl {
  Handler handler;
  StreamFeed feed;
  HttpLimits limits;
  SlowLane slow_lane;
  HttpServer* owner = nullptr;

  // Declared before the io_context: connections still queued in it at destruction count down here.
  std::unordered_map<std::string, std::size_t> per_address;  //!< connections of each client address
  std::size_t connections = 0;
  std::unordered_map<http_detail::StreamSink*, std::weak_ptr<http_detail::StreamSink>> streams;
  std::size_t queued = 0;                                        //!< requests waiting for a worker
  std::size_t slow_held = 0;                                     //!< slow requests waiting or running
  std::unordered_map<std::string, std::size_t> slow_by_address;  //!< of them, per client address
  std::uint64_t cursor = 0;  //!< stream messages up to this id are in every stream's buffer
  std::int64_t broadcast_ns = 0;
  bool pace_armed = false;
  std::atomic<bool> notified{false};
  std::optional<http_detail::net::ssl::context> tls;

  http_detail::net::io_context io{1};
  http_detail::net::ip::tcp::acceptor acceptor{io};
  http_detail::net::steady_timer pulse{io};       //!< keep-alives and held-back messages, every 100 ms
  http_detail::net::steady_timer pace_timer{io};  //!< the next batch of messages, when paced
  http_detail::net::steady_timer accept_pause{io};
  std::optional<http_detail::net::thread_pool> workers;
  std::optional<http_detail::net::thread_pool> slow_workers;
  std::thread io_thread;

  std::size_t input_cap() const { return limits.max_head_bytes + limits.max_body_bytes + 16384; }

  //! Counts a request in (503 when its queue is full, 429 when its address holds its share of the slow
  //! lane, 0 when admitted); `release` counts it out when answered. I/O thread only.
  int admit(bool slow, const std::string& remote);
  void release(bool slow, const std::string& remote);
  //! The handler's answer, 500 when it throws (a worker thread).
  HttpResponse run_handler(const HttpRequest& request) const;

  void add_stream(const std::shared_ptr<http_detail::StreamSink>& sink);
  void remove_stream(http_detail::StreamSink* sink);
  //! New messages (or a keep-alive comment) to every stream, no more often than pace_s() apart;
  //! `messages_only`: now, and no keep-alive.
  void broadcast(std::int64_t now, bool messages_only = false);
  double pace_s() const;
  void poke();  //!< new messages: a batch now, or when the pace allows
  void pulse_every_100ms();

  void accept_next();
  void on_accept(http_detail::net::ip::tcp::socket socket);
  void connection_closed(const std::string& remote);
};

}  // namespace tetra::ground
