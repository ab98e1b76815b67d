#pragma once
// One connection of the ground's HTTP server (http_server_impl.hpp) over a Beast stream, plain
// (beast::tcp_stream) or TLS (beast::ssl_stream of one): reads a request within its deadline (Beast's
// per-operation timeouts: idle, then the whole request), parses it (parse_request: Beast's parser and
// the strict checks of http_parse.hpp), hands it to a worker and reads nothing more meanwhile (a client
// that sends but never reads fills only the kernel's buffers), writes the answer within its own deadline
// (closed at once, what the kernel holds discarded, when missed), or turns into an event stream.

#include <spdlog/spdlog.h>

#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core/stream_traits.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/write.hpp>
#include <boost/beast/ssl/ssl_stream.hpp>
#include <sstream>
#include <type_traits>
#include <vector>

#include "http_server_impl.hpp"

namespace tetra::ground::http_detail {

namespace beast = boost::beast;
using TlsStream = beast::ssl_stream<beast::tcp_stream>;

//! The head of a response as Beast writes it: status line, the given fields, the security headers.
std::string response_head(const HttpResponse& res, std::size_t length, bool keep_alive);
//! The head of an event stream.
std::string stream_head(const HttpResponse& res);

template <class Stream>
class Connection : public StreamSink, public std::enable_shared_from_this<Connection<Stream>> {
 public:
  template <class... Args>
  Connection(HttpServer::Impl& server, std::string remote, Args&&... stream_args)
      : s_(server), stream_(std::forward<Args>(stream_args)...), remote_(std::move(remote)) {}
  ~Connection() override {
    if (streaming_) s_.remove_stream(this);
    s_.connection_closed(remote_);
  }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  void start() {
    if constexpr (kTls) {
      lowest().expires_after(seconds(s_.limits.request_timeout_s));
      stream_.async_handshake(net::ssl::stream_base::server, [self = this->shared_from_this()](auto ec) {
        if (!ec) self->read_more();
      });
    } else {
      read_more();
    }
  }

  void push(const std::shared_ptr<const std::string>& chunk) override {
    if (closed_) return;
    if (pending_ + chunk->size() > s_.limits.stream_buffer_bytes) {
      spdlog::warn("ground: event stream to {} closed: {} bytes not read (a slow reader; it may resume)",
                   remote_, pending_);
      return close();
    }
    chunks_.push_back(chunk);
    pending_ += chunk->size();
    if (!writing_) write_chunks();
  }

 private:
  static constexpr bool kTls = std::is_same_v<Stream, TlsStream>;
  beast::tcp_stream& lowest() { return beast::get_lowest_layer(stream_); }

  //! What the kernel still holds for this connection is discarded when it is closed (a client past
  //! its deadline is not fed from the kernel's buffers either); `false`: an ordinary close.
  void abort_on_close(bool abort) {
    boost::system::error_code ec;
    lowest().socket().set_option(net::socket_base::linger(abort, 0), ec);
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    abort_on_close(true);
    lowest().close();
  }

  void read_more() {
    if (s_.limits.idle_timeout_s > 0 && in_.empty()) {
      lowest().expires_after(seconds(s_.limits.idle_timeout_s));
    } else {
      lowest().expires_at(request_start_ + seconds(s_.limits.request_timeout_s));
    }
    const std::size_t have = in_.size();
    const std::size_t room = std::min<std::size_t>(have == 0 ? 2048 : 16384, s_.input_cap() - have);
    in_.resize(have + room);
    stream_.async_read_some(
        net::buffer(in_.data() + have, room),
        [self = this->shared_from_this(), have](auto ec, std::size_t n) { self->on_read(ec, have, n); });
  }

  void on_read(const boost::system::error_code& ec, std::size_t had, std::size_t n) {
    in_.resize(had + n);
    if (ec) {
      if (ec == beast::error::timeout && had > 0)
        spdlog::info("ground: request from {} not complete within {} s: closed", remote_,
                     s_.limits.request_timeout_s);
      return;  // the last hold on the connection: closed
    }
    if (had == 0) request_start_ = std::chrono::steady_clock::now();
    parse();
  }

  void parse() {
    auto parsed = parse_request(in_, {s_.limits.max_head_bytes, s_.limits.max_body_bytes});
    if (parsed.kind == ParseOutcome::Kind::kIncomplete) {
      if (in_.size() < s_.input_cap()) read_more();
      return;
    }
    if (parsed.kind == ParseOutcome::Kind::kRefused) return refuse(parsed.status, parsed.message, {});
    in_.erase(0, parsed.consumed);
    request_start_ = std::chrono::steady_clock::now();
    HttpRequest& req = parsed.request;
    req.remote_addr = remote_;
    req.tls = kTls;
    head_only_ = req.method == "HEAD";
    dispatch(std::move(req), parsed.keep_alive);
  }

  void refuse(int status, const std::string& message,
              std::vector<std::pair<std::string, std::string>> headers) {
    HttpResponse res;
    res.status = status;
    res.body = error_body(message);
    res.headers = std::move(headers);
    respond(std::move(res), false);
  }

  //! To a worker (the slow lane's or the others'), and its answer back to the I/O thread.
  void dispatch(HttpRequest req, bool keep_alive) {
    const bool slow = s_.slow_lane && s_.slow_lane(req);
    const int refusal = s_.admit(slow, remote_);
    if (refusal == 503) return refuse(503, "busy: too many requests waiting", {});
    if (refusal == 429)
      return refuse(429, "wait for your other request to be answered", {{"Retry-After", "1"}});
    auto& pool = slow ? *s_.slow_workers : *s_.workers;
    net::post(pool, [self = this->shared_from_this(), req = std::move(req), keep_alive, slow]() mutable {
      HttpResponse res = self->s_.run_handler(req);
      auto& io = self->s_.io;
      net::post(io, [self = std::move(self), res = std::move(res), keep_alive, slow]() mutable {
        self->s_.release(slow, self->remote_);
        self->respond(std::move(res), keep_alive);
      });
    });
  }

  void respond(HttpResponse res, bool keep_alive) {
    if (head_only_ && res.stream) {  // the head of a stream, nothing after it
      res.stream = false;
      res.content_type = "text/event-stream";
      res.body.clear();
    }
    if (res.stream && res.status == 200) {
      if (s_.streams.size() < s_.limits.max_streams) return start_stream(std::move(res));
      spdlog::warn("ground: event stream from {} refused (503): {} streams open, the limit", remote_,
                   s_.streams.size());
      res = HttpResponse{};
      res.status = 503;
      res.body = error_body("too many event streams open");
      keep_alive = false;
    }
    body_ = res.shared_body ? std::move(res.shared_body)
                            : std::make_shared<const std::string>(std::move(res.body));
    head_ = response_head(res, body_->size(), keep_alive);
    if (head_only_) body_.reset();
    write_response(keep_alive);
  }

  void write_response(bool keep_alive) {
    const std::size_t size = head_.size() + (body_ ? body_->size() : 0);
    lowest().expires_after(seconds(s_.limits.write_timeout_s +
                                   static_cast<double>(size) / std::max(1.0, s_.limits.min_write_rate)));
    abort_on_close(true);
    std::vector<net::const_buffer> out{net::buffer(head_)};
    if (body_) out.push_back(net::buffer(*body_));
    net::async_write(stream_, out, [self = this->shared_from_this(), keep_alive](auto ec, std::size_t) {
      self->on_written(ec, keep_alive);
    });
  }

  void on_written(const boost::system::error_code& ec, bool keep_alive) {
    if (ec) {
      if (ec == beast::error::timeout)
        spdlog::info("ground: {} has not read its answer by its deadline ({} s + {} B/s): closed", remote_,
                     s_.limits.write_timeout_s, s_.limits.min_write_rate);
      return;
    }
    abort_on_close(false);
    head_.clear();
    body_.reset();
    head_only_ = false;
    if (!keep_alive) {
      boost::system::error_code ignored;
      lowest().socket().shutdown(net::ip::tcp::socket::shutdown_send, ignored);
      return;
    }
    if (in_.empty()) {
      if (in_.capacity() > 4096) std::string().swap(in_);
      return read_more();
    }
    parse();
  }

  void start_stream(HttpResponse res) {
    std::string first = stream_head(res) + res.stream_start;
    if (res.stream_after > s_.cursor) s_.broadcast(now_ns(), true);
    for (std::uint64_t after = res.stream_after; after < s_.cursor;) {
      const std::uint64_t next = s_.feed.next(after, first);
      if (next == after) break;
      after = next;
    }
    streaming_ = true;
    s_.add_stream(this->shared_from_this());
    std::string().swap(in_);
    // A stream's client has nothing more to say: its bytes are read and dropped, its FIN ends it.
    lowest().expires_never();
    discard_input();
    abort_on_close(true);
    pending_ = first.size();  // the catch-up, whatever its size: the bound is on what follows
    chunks_.push_back(std::make_shared<const std::string>(std::move(first)));
    write_chunks();
  }

  void discard_input() {
    stream_.async_read_some(net::buffer(sink_), [self = this->shared_from_this()](auto ec, std::size_t) {
      if (ec) return self->close();
      self->discard_input();
    });
  }

  void write_chunks() {
    writing_ = true;
    in_flight_ = chunks_.size();  // their text stays put while more are queued behind them
    std::vector<net::const_buffer> out;
    out.reserve(in_flight_);
    for (const auto& c : chunks_) out.push_back(net::buffer(*c));
    lowest().expires_after(seconds(s_.limits.write_timeout_s));  // the read has no deadline: unchanged
    net::async_write(stream_, out, [self = this->shared_from_this()](auto ec, std::size_t) {
      self->on_chunks_written(ec);
    });
  }

  void on_chunks_written(const boost::system::error_code& ec) {
    writing_ = false;
    if (ec) {
      if (ec == beast::error::timeout)
        spdlog::info("ground: event stream to {} behind for {} s: closed (it may resume)", remote_,
                     s_.limits.write_timeout_s);
      return close();
    }
    for (std::size_t i = 0; i < in_flight_; ++i) pending_ -= chunks_[i]->size();
    chunks_.erase(chunks_.begin(), chunks_.begin() + static_cast<std::ptrdiff_t>(in_flight_));
    in_flight_ = 0;
    if (!chunks_.empty() && !closed_) write_chunks();
  }

  HttpServer::Impl& s_;
  Stream stream_;
  std::string remote_;
  std::string in_;  //!< bytes read and not yet taken by a request
  std::chrono::steady_clock::time_point request_start_{};
  bool head_only_ = false;  //!< the request being answered is a HEAD
  std::string head_;
  std::shared_ptr<const std::string> body_;
  // An event stream's state: the batches not yet written (shared with every other stream).
  bool streaming_ = false;
  bool closed_ = false;
  bool writing_ = false;
  std::vector<std::shared_ptr<const std::string>> chunks_;
  std::size_t in_flight_ = 0;  //!< the first chunks_, being written
  std::size_t pending_ = 0;    //!< bytes in chunks_
  char sink_[64] = {};
};

}  // namespace tetra::ground::http_detail
