#include "tetra/ground/http_server.hpp"

#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <algorithm>
#include <boost/asio/post.hpp>
#include <boost/beast/http/write.hpp>
#include <sstream>
#include <vector>

#include "http_connection.hpp"
#include "http_server_impl.hpp"
#include "http_socket.hpp"

namespace tetra::ground {

namespace http_detail {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

namespace {

namespace http = beast::http;

void add_fields(http::response_header<>& h, const HttpResponse& res) {
  h.set("X-Content-Type-Options", "nosniff");
  h.set("X-Frame-Options", "DENY");
  h.set("Content-Security-Policy", "frame-ancestors 'none'");
  h.set("Referrer-Policy", "no-referrer");
  for (const auto& [k, v] : res.headers) h.insert(k, v);
}

std::string text_of(const http::response_header<>& h) {
  std::ostringstream os;
  os << h;
  return os.str();
}

}  // namespace

std::string response_head(const HttpResponse& res, std::size_t length, bool keep_alive) {
  http::response_header<> h;
  h.version(11);
  h.result(static_cast<unsigned>(res.status));
  h.reason(reason_phrase(res.status));
  h.set(http::field::content_type, res.content_type);
  h.set(http::field::content_length, std::to_string(length));
  add_fields(h, res);
  if (!keep_alive) h.set(http::field::connection, "close");
  return text_of(h);
}

std::string stream_head(const HttpResponse& res) {
  http::response_header<> h;
  h.version(11);
  h.result(http::status::ok);
  h.set(http::field::content_type, "text/event-stream");
  h.set(http::field::cache_control, "no-cache");
  h.set("X-Accel-Buffering", "no");
  add_fields(h, res);
  return text_of(h);
}

}  // namespace http_detail

using http_detail::net::ip::tcp;
namespace net = http_detail::net;

int HttpServer::Impl::admit(bool slow, const std::string& remote) {
  if (!slow) {
    if (queued >= limits.max_queued) return 503;
    ++queued;
    return 0;
  }
  if (slow_held >= limits.max_slow_queued) return 503;
  auto& here = slow_by_address[remote];
  if (here >= limits.max_slow_per_address) return 429;
  ++here;
  ++slow_held;
  return 0;
}

void HttpServer::Impl::release(bool slow, const std::string& remote) {
  if (!slow) {
    --queued;
    return;
  }
  --slow_held;
  if (const auto it = slow_by_address.find(remote); it != slow_by_address.end() && --it->second == 0)
    slow_by_address.erase(it);
}

HttpResponse HttpServer::Impl::run_handler(const HttpRequest& request) const {
  try {
    return handler(request);
  } catch (const std::exception& e) {
    spdlog::error("ground: {} {}: {}", one_line(request.method), one_line(request.path), e.what());
    HttpResponse res;
    res.status = 500;
    res.body = error_body("internal error");
    return res;
  }
}

void HttpServer::Impl::add_stream(const std::shared_ptr<http_detail::StreamSink>& sink) {
  streams.emplace(sink.get(), sink);
  owner->streams_ = streams.size();
}

void HttpServer::Impl::remove_stream(http_detail::StreamSink* sink) {
  streams.erase(sink);
  if (owner != nullptr) owner->streams_ = streams.size();
}

//! [s] between two batches of messages: 0.1 ms a stream, from 2 ms (up to 20 streams) to 100 ms
//! (1,000 and more): the writes per second stay about the same however many streams are open.
double HttpServer::Impl::pace_s() const {
  return std::clamp(1e-4 * static_cast<double>(streams.size()), 0.002, 0.1);
}

void HttpServer::Impl::broadcast(std::int64_t now, bool messages_only) {
  const auto ns = [](double s) { return static_cast<std::int64_t>(s * 1e9); };
  if (!messages_only && now - broadcast_ns < ns(pace_s())) return;
  std::string text;
  const std::uint64_t last = feed.last();
  while (cursor < last && text.size() < (4U << 20)) {
    const std::uint64_t next = feed.next(cursor, text);
    if (next == cursor) break;
    cursor = next;
  }
  if (text.empty()) {
    if (messages_only || now - broadcast_ns < ns(limits.keepalive_s)) return;
    text = ": keep-alive\n\n";
  }
  broadcast_ns = now;
  const auto chunk = std::make_shared<const std::string>(std::move(text));
  std::vector<std::shared_ptr<http_detail::StreamSink>> held;
  held.reserve(streams.size());
  for (const auto& [raw, weak] : streams) {
    if (auto sink = weak.lock()) held.push_back(std::move(sink));
  }
  for (const auto& sink : held) sink->push(chunk);
}

void HttpServer::Impl::poke() {
  if (pace_armed) return;
  const auto wait_ns = broadcast_ns + static_cast<std::int64_t>(pace_s() * 1e9) - http_detail::now_ns();
  if (wait_ns <= 0) return broadcast(http_detail::now_ns());
  pace_armed = true;
  pace_timer.expires_after(std::chrono::nanoseconds(wait_ns));
  pace_timer.async_wait([this](const boost::system::error_code& ec) {
    pace_armed = false;
    if (ec) return;
    broadcast(http_detail::now_ns());
    if (feed.last() > cursor) poke();  // more than one batch held back
  });
}

void HttpServer::Impl::pulse_every_100ms() {
  pulse.expires_after(std::chrono::milliseconds(100));
  pulse.async_wait([this](const boost::system::error_code& ec) {
    if (ec) return;
    broadcast(http_detail::now_ns());
    pulse_every_100ms();
  });
}

void HttpServer::Impl::accept_next() {
  acceptor.async_accept([this](const boost::system::error_code& ec, tcp::socket socket) {
    if (!ec) {
      on_accept(std::move(socket));
      return accept_next();
    }
    if (ec == net::error::operation_aborted) return;
    // Out of descriptors or memory: the connections held are served meanwhile.
    accept_pause.expires_after(std::chrono::milliseconds(50));
    accept_pause.async_wait([this](const boost::system::error_code& e) {
      if (!e) accept_next();
    });
  });
}

void HttpServer::Impl::on_accept(tcp::socket socket) {
  boost::system::error_code ec;
  const auto peer = socket.remote_endpoint(ec);
  std::string remote = ec ? std::string("?") : peer.address().to_string();
  auto& from_there = per_address[remote];
  if (connections >= limits.max_connections || from_there >= limits.max_connections_per_address) {
    if (from_there == 0) per_address.erase(remote);
    return;  // closed at once
  }
  ++from_there;
  ++connections;
  socket.set_option(tcp::no_delay(true), ec);
  if (tls) {
    std::make_shared<http_detail::Connection<http_detail::TlsStream>>(*this, std::move(remote),
                                                                      std::move(socket), *tls)
        ->start();
  } else {
    std::make_shared<http_detail::Connection<http_detail::beast::tcp_stream>>(*this, std::move(remote),
                                                                              std::move(socket))
        ->start();
  }
}

void HttpServer::Impl::connection_closed(const std::string& remote) {
  --connections;
  if (const auto it = per_address.find(remote); it != per_address.end() && --it->second == 0)
    per_address.erase(it);
}

HttpServer::HttpServer(Handler handler, StreamFeed feed, HttpLimits limits, SlowLane slow)
    : impl_(std::make_unique<Impl>()) {
  impl_->handler = std::move(handler);
  impl_->slow_lane = std::move(slow);
  impl_->feed = std::move(feed);
  impl_->limits = limits;
  impl_->owner = this;
}

HttpServer::~HttpServer() {
  stop();
  impl_->owner = nullptr;  // connections still queued count down in the Impl alone
}

void HttpServer::notify() {
  auto& m = *impl_;
  if (!m.notified.exchange(true)) {
    net::post(m.io, [&m] {
      m.notified = false;
      m.poke();
    });
  }
}

Status HttpServer::start(const std::string& host, int port, const TlsFiles& tls) {
  auto& m = *impl_;
  // Every held stream is a descriptor: use the hard limit.
  rlimit files{};
  if (::getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
    files.rlim_cur = files.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &files);
  }
  if (!tls.cert.empty()) {
    if (auto s = http_detail::make_tls_context(tls, m.tls); !s) return s;
  }
  if (auto s = http_detail::listen_on(m.acceptor, host, port, port_); !s) return s;
  m.cursor = m.feed.last();
  m.workers.emplace(static_cast<std::size_t>(std::max(1, m.limits.workers)));
  m.slow_workers.emplace(static_cast<std::size_t>(std::max(1, m.limits.slow_workers)));
  m.accept_next();
  m.pulse_every_100ms();
  m.io_thread = std::thread([&m] { m.io.run(); });
  return ok_status();
}

void HttpServer::stop() {
  auto& m = *impl_;
  m.io.stop();
  if (m.io_thread.joinable()) m.io_thread.join();
  for (auto* pool : {&m.workers, &m.slow_workers}) {
    if (!*pool) continue;
    (*pool)->stop();
    (*pool)->join();
  }
}

}  // namespace tetra::ground
