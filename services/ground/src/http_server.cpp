#include "tetra/ground/http_server.hpp"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <spdlog/spdlog.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <unordered_map>
#include <unordered_set>

#include "http_socket.hpp"

namespace tetra::ground {

namespace {

std::int64_t io_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::int64_t to_ns(double s) {
  return static_cast<std::int64_t>(s * 1e9);
}

}  // namespace

namespace http_detail {

struct Conn {
  enum class State { kReading, kWorking, kWriting, kStream };
  std::uint64_t id = 0;
  int fd = -1;
  SSL* ssl = nullptr;
  std::string remote;
  State state = State::kReading;
  std::string in;
  std::string out;
  std::size_t out_off = 0;
  std::shared_ptr<const std::string> body;
  std::size_t body_off = 0;
  //! A stream's messages: shared by every stream (one copy however many streams hold it).
  std::deque<std::shared_ptr<const std::string>> chunks;
  std::size_t chunk_off = 0;    //!< written of chunks.front()
  std::size_t chunk_bytes = 0;  //!< in chunks
  bool close_after = false;
  bool want_in = true;  //!< EPOLLIN asked for
  bool want_out = false;
  bool peer_closed = false;  //!< the client sent FIN: its requests read are still answered, then closed
  bool head_only = false;    //!< the request being answered is a HEAD
  std::int64_t accepted_ns = 0;
  std::int64_t response_deadline_ns = 0;  //!< [ns] the response being written must be out by then
  std::int64_t backlog_since_ns = 0;      //!< [ns] a stream's buffer not empty since (0: empty)
  std::int64_t request_start_ns = 0;      //!< [ns] first byte of the request being read (0: none yet)
  std::int64_t activity_ns = 0;           //!< [ns] last byte read or written
  std::size_t pending() const {
    return out.size() - out_off + (body ? body->size() - body_off : 0) + chunk_bytes - chunk_off;
  }
};

struct Job {
  std::uint64_t conn = 0;
  HttpRequest request;
  bool keep_alive = false;
  bool slow = false;
};
struct Done {
  std::uint64_t conn = 0;
  HttpResponse response;
  bool keep_alive = false;
};

}  // namespace http_detail

namespace {
using http_detail::Conn;
using http_detail::Done;
using http_detail::Job;
constexpr std::uint64_t kListenId = 0;
constexpr std::uint64_t kWakeId = 1;
}  // namespace

struct HttpServer::Impl {
  Handler handler;
  StreamFeed feed;
  HttpLimits limits;
  SlowLane slow_lane;
  HttpServer* owner = nullptr;
  int listen_fd = -1;
  int epoll_fd = -1;
  int wake_fd = -1;
  SSL_CTX* ssl_ctx = nullptr;
  std::unordered_map<std::uint64_t, std::unique_ptr<Conn>> conns;
  std::unordered_set<std::uint64_t> streams;
  std::unordered_map<std::string, std::size_t> per_address;  //!< connections of each client address
  std::uint64_t next_id = 2;
  std::uint64_t cursor = 0;  //!< stream messages up to this id are in every stream's buffer
  std::int64_t broadcast_ns = 0;
  std::int64_t swept_ns = 0;
  std::atomic<bool> stopping{false};
  std::mutex mutex;
  std::condition_variable work;
  std::condition_variable slow_work;
  std::deque<Job> jobs;
  std::deque<Job> slow_jobs;
  std::size_t slow_held = 0;                                     //!< slow requests waiting or running
  std::unordered_map<std::string, std::size_t> slow_by_address;  //!< of them, per client address
  std::deque<Done> done;
  std::vector<std::thread> workers;
  std::thread io;

  ~Impl() {
    for (auto& [id, c] : conns) close_socket(*c);
    if (listen_fd >= 0) ::close(listen_fd);
    if (epoll_fd >= 0) ::close(epoll_fd);
    if (wake_fd >= 0) ::close(wake_fd);
    if (ssl_ctx != nullptr) SSL_CTX_free(ssl_ctx);
  }

  void wake() const {
    const std::uint64_t one = 1;
    [[maybe_unused]] const auto n = ::write(wake_fd, &one, sizeof one);
  }

  static void close_socket(Conn& c) {
    if (c.ssl != nullptr) SSL_free(c.ssl);
    c.ssl = nullptr;
    if (c.fd >= 0) ::close(c.fd);
    c.fd = -1;
  }

  //! Closes the connection; `abort`: at once, what the kernel still holds for it discarded (a client
  //! past its deadline is not fed from the kernel's buffers either).
  void drop(Conn& c, bool abort = false) {
    if (abort) {
      const linger now{1, 0};
      ::setsockopt(c.fd, SOL_SOCKET, SO_LINGER, &now, sizeof now);
    }
    if (c.state == Conn::State::kStream) {
      streams.erase(c.id);
      owner->streams_ = streams.size();
    }
    if (const auto it = per_address.find(c.remote); it != per_address.end() && --it->second == 0)
      per_address.erase(it);
    ::epoll_ctl(epoll_fd, EPOLL_CTL_DEL, c.fd, nullptr);
    close_socket(c);
    conns.erase(c.id);  // destroys c
  }

  std::size_t input_cap() const { return limits.max_head_bytes + limits.max_body_bytes + 16384; }

  //! Asks epoll for what the connection can use: input while its buffer has room (a client that sends
  //! but never reads is not read further: its buffer stays bounded), output while anything is pending.
  void interest(Conn& c) {
    const bool in = !c.peer_closed && (c.state == Conn::State::kStream || c.in.size() < input_cap());
    const bool out = c.pending() > 0;
    if (c.want_in == in && c.want_out == out) return;
    c.want_in = in;
    c.want_out = out;
    epoll_event ev{};
    ev.events = (in ? EPOLLIN : 0U) | (out ? EPOLLOUT : 0U);
    ev.data.u64 = c.id;
    ::epoll_ctl(epoll_fd, EPOLL_CTL_MOD, c.fd, &ev);
  }

  void accept_all(std::int64_t now) {
    for (;;) {
      sockaddr_storage addr{};
      socklen_t len = sizeof addr;
      const int fd =
          ::accept4(listen_fd, reinterpret_cast<sockaddr*>(&addr), &len, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) return;
      std::string remote = http_detail::address_text(addr);
      auto& from_there = per_address[remote];
      if (conns.size() >= limits.max_connections || from_there >= limits.max_connections_per_address) {
        if (from_there == 0) per_address.erase(remote);
        ::close(fd);
        continue;
      }
      ++from_there;
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      auto c = std::make_unique<Conn>();
      c->id = next_id++;
      c->fd = fd;
      c->accepted_ns = c->activity_ns = now;
      c->remote = std::move(remote);
      if (ssl_ctx != nullptr) {
        c->ssl = SSL_new(ssl_ctx);
        SSL_set_fd(c->ssl, fd);
        SSL_set_accept_state(c->ssl);
      }
      epoll_event ev{};
      ev.events = EPOLLIN;
      ev.data.u64 = c->id;
      ::epoll_ctl(epoll_fd, EPOLL_CTL_ADD, fd, &ev);
      conns.emplace(c->id, std::move(c));
    }
  }

  void on_readable(Conn& c, std::int64_t now) {
    char buf[16384];
    const std::uint64_t id = c.id;
    while (c.state == Conn::State::kStream || c.in.size() < input_cap()) {
      const long r = http_detail::read_some(c.fd, c.ssl, buf, sizeof buf);
      if (r == -1) break;
      if (r == -2) return drop(c);
      if (r == 0) {
        c.peer_closed = true;
        break;
      }
      if (c.state == Conn::State::kStream) continue;  // a stream's client has nothing to say
      if (c.in.empty() && c.request_start_ns == 0) c.request_start_ns = now;
      c.in.append(buf, static_cast<std::size_t>(r));
      c.activity_ns = now;
    }
    if (c.state == Conn::State::kReading) parse(c, now);
    if (conns.count(id) == 0) return;
    // FIN: what was asked is answered first; nothing more will come.
    if (c.peer_closed && (c.state == Conn::State::kReading || c.state == Conn::State::kStream))
      return drop(c);
    interest(c);
  }

  void refuse(Conn& c, int status, const std::string& message) {
    HttpResponse res;
    res.status = status;
    res.body = error_body(message);
    respond(c, std::move(res), false);
  }

  void parse(Conn& c, std::int64_t now) {
    auto parsed = parse_request(c.in, {limits.max_head_bytes, limits.max_body_bytes});
    if (parsed.kind == ParseOutcome::Kind::kIncomplete) return;
    if (parsed.kind == ParseOutcome::Kind::kRefused) return refuse(c, parsed.status, parsed.message);
    c.in.erase(0, parsed.consumed);
    c.request_start_ns = c.in.empty() ? 0 : now;
    HttpRequest& req = parsed.request;
    req.remote_addr = c.remote;
    req.tls = c.ssl != nullptr;
    c.head_only = req.method == "HEAD";
    const bool slow = slow_lane && slow_lane(req);
    int refusal = 0;
    {
      const std::lock_guard lock(mutex);
      auto& held_here = slow_by_address[c.remote];
      if (slow && slow_held >= limits.max_slow_queued) {
        refusal = 503;
      } else if (slow && held_here >= limits.max_slow_per_address) {
        refusal = 429;
      } else if (!slow && jobs.size() >= limits.max_queued) {
        refusal = 503;
      } else {
        c.state = Conn::State::kWorking;
        if (slow) {
          ++slow_held;
          ++held_here;
          slow_jobs.push_back({c.id, std::move(req), parsed.keep_alive, true});
          slow_work.notify_one();
        } else {
          jobs.push_back({c.id, std::move(req), parsed.keep_alive, false});
          work.notify_one();
        }
      }
      if (held_here == 0) slow_by_address.erase(c.remote);
    }
    if (refusal == 503) return refuse(c, 503, "busy: too many requests waiting");
    if (refusal == 429) {
      HttpResponse res;
      res.status = 429;
      res.body = error_body("wait for your other request to be answered");
      res.headers.emplace_back("Retry-After", "1");
      respond(c, std::move(res), false);
    }
  }

  static void add_common_headers(std::string& head) {
    head +=
        "X-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\n"
        "Content-Security-Policy: frame-ancestors 'none'\r\nReferrer-Policy: no-referrer\r\n";
  }

  void respond(Conn& c, HttpResponse res, bool keep_alive) {
    keep_alive = keep_alive && !c.peer_closed;
    if (c.head_only && res.stream) {  // the head of a stream, nothing after it
      res.stream = false;
      res.content_type = "text/event-stream";
      res.body.clear();
    }
    if (res.stream && res.status == 200) {
      if (streams.size() >= limits.max_streams) {
        spdlog::warn("ground: event stream from {} refused (503): {} streams open, the limit", c.remote,
                     streams.size());
        res = HttpResponse{};
        res.status = 503;
        res.body = "{\"error\":\"too many event streams open\"}";
        keep_alive = false;
      } else {
        std::string head =
            "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-cache\r\n"
            "X-Accel-Buffering: no\r\n";
        add_common_headers(head);
        for (const auto& [k, v] : res.headers) head += k + ": " + v + "\r\n";
        head += "\r\n";
        c.out += head + res.stream_start;
        if (res.stream_after > cursor) broadcast(io_now_ns(), true);
        for (std::uint64_t after = res.stream_after; after < cursor;) {
          const std::uint64_t next = feed.next(after, c.out);
          if (next == after) break;
          after = next;
        }
        c.state = Conn::State::kStream;
        streams.insert(c.id);
        owner->streams_ = streams.size();
        flush(c, io_now_ns());
        return;
      }
    }
    std::string head = "HTTP/1.1 " + std::to_string(res.status) + " " + reason_phrase(res.status) + "\r\n";
    const std::size_t length = res.shared_body ? res.shared_body->size() : res.body.size();
    head += "Content-Type: " + res.content_type + "\r\nContent-Length: " + std::to_string(length) + "\r\n";
    add_common_headers(head);
    for (const auto& [k, v] : res.headers) head += k + ": " + v + "\r\n";
    if (!keep_alive) head += "Connection: close\r\n";
    head += "\r\n";
    c.out += head;
    if (c.head_only) {
      // HEAD: the head alone, with the length the body would have.
    } else if (res.shared_body) {
      c.body = std::move(res.shared_body);
      c.body_off = 0;
    } else {
      c.out += res.body;
    }
    c.close_after = !keep_alive;
    c.state = Conn::State::kWriting;
    const std::int64_t now = io_now_ns();
    c.response_deadline_ns = now + to_ns(limits.write_timeout_s + static_cast<double>(c.pending()) /
                                                                      std::max(1.0, limits.min_write_rate));
    flush(c, now);
  }

  void flush(Conn& c, std::int64_t now) {
    while (c.pending() > 0) {
      const char* data = nullptr;
      std::size_t n = 0;
      std::size_t* advanced = nullptr;
      if (c.out_off < c.out.size()) {
        data = c.out.data() + c.out_off;
        n = c.out.size() - c.out_off;
        advanced = &c.out_off;
      } else if (c.body && c.body_off < c.body->size()) {
        data = c.body->data() + c.body_off;
        n = c.body->size() - c.body_off;
        advanced = &c.body_off;
      } else {
        data = c.chunks.front()->data() + c.chunk_off;
        n = c.chunks.front()->size() - c.chunk_off;
        advanced = &c.chunk_off;
      }
      const long w = http_detail::write_some(c.fd, c.ssl, data, n);
      if (w == -1) break;
      if (w <= 0) return drop(c);
      *advanced += static_cast<std::size_t>(w);
      c.activity_ns = now;
      if (advanced == &c.chunk_off && c.chunk_off == c.chunks.front()->size()) {
        c.chunk_bytes -= c.chunk_off;
        c.chunk_off = 0;
        c.chunks.pop_front();
      }
    }
    if (c.out_off == c.out.size()) {
      c.out.clear();
      c.out_off = 0;
    } else if (c.out_off > (1U << 16)) {
      c.out.erase(0, c.out_off);
      c.out_off = 0;
    }
    if (c.body && c.body_off == c.body->size()) c.body.reset();
    const bool pending = c.pending() > 0;
    c.backlog_since_ns = !pending ? 0 : (c.backlog_since_ns != 0 ? c.backlog_since_ns : now);
    if (!pending && c.state == Conn::State::kWriting) {
      if (c.close_after || (c.peer_closed && c.in.empty())) return drop(c);
      c.state = Conn::State::kReading;
      c.activity_ns = now;
      c.head_only = false;
      const std::uint64_t id = c.id;
      if (!c.in.empty()) parse(c, now);
      if (conns.count(id) == 0) return;
      if (c.peer_closed && c.state == Conn::State::kReading) return drop(c);
    }
    interest(c);
  }

  //! Appends the new stream messages (or a keep-alive comment) to every stream.
  //! [s] between two batches of messages: 0.1 ms a stream, from 2 ms (up to 20 streams) to 100 ms
  //! (1,000 and more): the writes per second stay about the same however many streams are open.
  double pace_s() const { return std::clamp(1e-4 * static_cast<double>(streams.size()), 0.002, 0.1); }

  //! Each stream gets a batch as one append, and a write when its socket has room.
  void broadcast(std::int64_t now, bool messages_only = false) {
    if (!messages_only && now - broadcast_ns < to_ns(pace_s())) return;
    std::string text;
    const std::uint64_t last = feed.last();
    while (cursor < last && text.size() < (4U << 20)) {
      const std::uint64_t next = feed.next(cursor, text);
      if (next == cursor) break;
      cursor = next;
    }
    if (text.empty()) {
      if (messages_only || now - broadcast_ns < to_ns(limits.keepalive_s)) return;
      text = ": keep-alive\n\n";
    }
    broadcast_ns = now;
    const auto chunk = std::make_shared<const std::string>(std::move(text));
    std::vector<std::uint64_t> ids(streams.begin(), streams.end());
    for (const auto id : ids) {
      Conn& c = *conns.at(id);
      if (c.pending() + chunk->size() > limits.stream_buffer_bytes) {
        spdlog::warn("ground: event stream to {} closed: {} bytes not read (a slow reader; it may resume)",
                     c.remote, c.pending());
        drop(c, true);
        continue;
      }
      const bool was_waiting = c.want_out;  // its socket is full: EPOLLOUT will flush it
      c.chunks.push_back(chunk);
      c.chunk_bytes += chunk->size();
      if (!was_waiting) flush(c, now);
    }
  }

  void collect_done() {
    std::deque<Done> ready;
    {
      const std::lock_guard lock(mutex);
      ready.swap(done);
    }
    for (auto& d : ready) {
      const auto it = conns.find(d.conn);
      if (it == conns.end() || it->second->state != Conn::State::kWorking) continue;
      respond(*it->second, std::move(d.response), d.keep_alive);
    }
  }

  void sweep(std::int64_t now) {
    std::vector<std::pair<std::uint64_t, bool>> expired;  // and whether output is left to discard
    for (const auto& [id, c] : conns) {
      switch (c->state) {
        case Conn::State::kReading:
          if (c->request_start_ns != 0 && now - c->request_start_ns > to_ns(limits.request_timeout_s)) {
            spdlog::info("ground: request from {} not complete within {} s: closed", c->remote,
                         limits.request_timeout_s);
            expired.emplace_back(id, false);
          } else if (c->request_start_ns == 0 && now - c->activity_ns > to_ns(limits.idle_timeout_s)) {
            expired.emplace_back(id, false);
          } else if (c->ssl != nullptr && !SSL_is_init_finished(c->ssl) &&
                     now - c->accepted_ns > to_ns(limits.request_timeout_s)) {
            expired.emplace_back(id, false);
          }
          break;
        case Conn::State::kWriting:
          if (now > c->response_deadline_ns ||
              (c->pending() > 0 && now - c->activity_ns > to_ns(limits.write_timeout_s))) {
            spdlog::info("ground: {} has not read its answer by its deadline ({} s + {} B/s): closed",
                         c->remote, limits.write_timeout_s, limits.min_write_rate);
            expired.emplace_back(id, true);
          }
          break;
        case Conn::State::kStream:
          if (c->backlog_since_ns != 0 && now - c->backlog_since_ns > to_ns(limits.write_timeout_s)) {
            spdlog::info("ground: event stream to {} behind for {} s: closed (it may resume)", c->remote,
                         limits.write_timeout_s);
            expired.emplace_back(id, true);
          }
          break;
        case Conn::State::kWorking:
          break;
      }
    }
    for (const auto& [id, abort] : expired) drop(*conns.at(id), abort);
  }

  void run() {
    std::vector<epoll_event> events(512);
    int wait_ms = 100;
    while (!stopping) {
      const int n = ::epoll_wait(epoll_fd, events.data(), static_cast<int>(events.size()), wait_ms);
      const std::int64_t now = io_now_ns();
      for (int i = 0; i < n; ++i) {
        const std::uint64_t id = events[static_cast<std::size_t>(i)].data.u64;
        const std::uint32_t what = events[static_cast<std::size_t>(i)].events;
        if (id == kListenId) {
          accept_all(now);
          continue;
        }
        if (id == kWakeId) {
          std::uint64_t count = 0;
          [[maybe_unused]] const auto r = ::read(wake_fd, &count, sizeof count);
          continue;
        }
        auto it = conns.find(id);
        if (it == conns.end()) continue;
        Conn& c = *it->second;
        if ((what & (EPOLLHUP | EPOLLERR)) != 0U && ((what & EPOLLIN) == 0U || c.peer_closed)) {
          drop(c);  // gone both ways: nothing can be written to it
          continue;
        }
        if ((what & EPOLLIN) != 0U) {
          on_readable(c, now);
          if (conns.count(id) == 0) continue;
        }
        if ((what & EPOLLOUT) != 0U) {
          if (c.ssl != nullptr && c.state == Conn::State::kReading) on_readable(c, now);
          if (conns.count(id) != 0) flush(c, now);
        }
      }
      collect_done();
      broadcast(now);
      wait_ms = feed.last() > cursor ? static_cast<int>(pace_s() * 1000) : 100;  // messages held back
      if (now - swept_ns > to_ns(0.1)) {
        swept_ns = now;
        sweep(now);
      }
    }
  }

  void serve_requests(bool slow) {
    std::deque<Job>& queue = slow ? slow_jobs : jobs;
    std::condition_variable& ready = slow ? slow_work : work;
    for (;;) {
      Job job;
      {
        std::unique_lock lock(mutex);
        ready.wait(lock, [&] { return stopping || !queue.empty(); });
        if (stopping) return;
        job = std::move(queue.front());
        queue.pop_front();
      }
      HttpResponse res;
      try {
        res = handler(job.request);
      } catch (const std::exception& e) {
        spdlog::error("ground: {} {}: {}", one_line(job.request.method), one_line(job.request.path),
                      e.what());
        res = HttpResponse{};
        res.status = 500;
        res.body = error_body("internal error");
      }
      {
        const std::lock_guard lock(mutex);
        if (job.slow) {
          --slow_held;
          if (const auto it = slow_by_address.find(job.request.remote_addr);
              it != slow_by_address.end() && --it->second == 0)
            slow_by_address.erase(it);
        }
        done.push_back({job.conn, std::move(res), job.keep_alive});
      }
      wake();
    }
  }
};

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
}

void HttpServer::notify() {
  if (impl_->wake_fd >= 0) impl_->wake();
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
    auto ctx = http_detail::make_tls_context(tls);
    if (!ctx) return ctx.error();
    m.ssl_ctx = *ctx;
  }
  auto listening = http_detail::listen_on(host, port, port_);
  if (!listening) return listening.error();
  m.listen_fd = *listening;
  m.epoll_fd = ::epoll_create1(EPOLL_CLOEXEC);
  m.wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (m.epoll_fd < 0 || m.wake_fd < 0) return failure("cannot create epoll or eventfd descriptors");
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.u64 = kListenId;
  ::epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, m.listen_fd, &ev);
  ev.data.u64 = kWakeId;
  ::epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, m.wake_fd, &ev);
  m.cursor = m.feed.last();
  for (int i = 0; i < m.limits.workers; ++i) m.workers.emplace_back([&m] { m.serve_requests(false); });
  if (m.slow_lane) {
    for (int i = 0; i < m.limits.slow_workers; ++i) m.workers.emplace_back([&m] { m.serve_requests(true); });
  }
  m.io = std::thread([&m] { m.run(); });
  return ok_status();
}

void HttpServer::stop() {
  auto& m = *impl_;
  {
    const std::lock_guard lock(m.mutex);
    m.stopping = true;
  }
  m.work.notify_all();
  m.slow_work.notify_all();
  if (m.wake_fd >= 0) m.wake();
  if (m.io.joinable()) m.io.join();
  for (auto& w : m.workers) {
    if (w.joinable()) w.join();
  }
  m.workers.clear();
}

}  // namespace tetra::ground
