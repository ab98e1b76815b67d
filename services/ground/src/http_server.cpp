#include "tetra/ground/http_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <openssl/err.h>
#include <openssl/ssl.h>
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

namespace tetra::ground {

std::string HttpRequest::header(const std::string& name) const {
  const auto it = headers.find(name);
  return it == headers.end() ? std::string() : it->second;
}

namespace {

std::int64_t io_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::int64_t to_ns(double s) {
  return static_cast<std::int64_t>(s * 1e9);
}

const char* reason_phrase(int status) {
  switch (status) {
    case 200:
      return "OK";
    case 302:
      return "Found";
    case 400:
      return "Bad Request";
    case 401:
      return "Unauthorized";
    case 403:
      return "Forbidden";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 408:
      return "Request Timeout";
    case 413:
      return "Payload Too Large";
    case 415:
      return "Unsupported Media Type";
    case 431:
      return "Request Header Fields Too Large";
    case 500:
      return "Internal Server Error";
    case 501:
      return "Not Implemented";
    case 503:
      return "Service Unavailable";
    case 504:
      return "Gateway Timeout";
    default:
      return "Status";
  }
}

std::string to_lower(std::string s) {
  for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

//! Percent-decoding (and '+' as space in a query); false on a bad escape or a NUL.
bool url_decode(const std::string& in, bool plus_is_space, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    char ch = in[i];
    if (ch == '%') {
      if (i + 2 >= in.size()) return false;
      const auto hex = [](char h) {
        return h >= '0' && h <= '9'
                   ? h - '0'
                   : (h >= 'a' && h <= 'f' ? h - 'a' + 10 : (h >= 'A' && h <= 'F' ? h - 'A' + 10 : -1));
      };
      const int hi = hex(in[i + 1]);
      const int lo = hex(in[i + 2]);
      if (hi < 0 || lo < 0) return false;
      ch = static_cast<char>(hi * 16 + lo);
      i += 2;
    } else if (ch == '+' && plus_is_space) {
      ch = ' ';
    }
    if (ch == '\0') return false;
    out += ch;
  }
  return true;
}

//! The request line and headers (up to the blank line) and the HTTP version; an error names what is wrong.
Result<HttpRequest> parse_head(const std::string& head, std::string& version) {
  HttpRequest req;
  const auto line_end = head.find("\r\n");
  const std::string line = head.substr(0, line_end);
  const auto sp1 = line.find(' ');
  const auto sp2 = line.rfind(' ');
  if (sp1 == std::string::npos || sp2 == sp1) return bad_input("malformed request line");
  req.method = line.substr(0, sp1);
  const std::string target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  version = line.substr(sp2 + 1);
  if (version != "HTTP/1.1" && version != "HTTP/1.0") return bad_input("HTTP/1.0 or HTTP/1.1 only");
  if (target.empty() || target[0] != '/') return bad_input("the request target must be a path");
  const auto q = target.find('?');
  if (!url_decode(target.substr(0, q), false, req.path))
    return bad_input("path: bad percent-encoding or NUL");
  if (q != std::string::npos) {
    std::size_t start = q + 1;
    while (start <= target.size()) {
      auto amp = target.find('&', start);
      if (amp == std::string::npos) amp = target.size();
      const std::string pair = target.substr(start, amp - start);
      start = amp + 1;
      if (pair.empty()) continue;
      const auto eq = pair.find('=');
      std::string name;
      std::string value;
      if (!url_decode(pair.substr(0, eq), true, name)) return bad_input("query: bad percent-encoding or NUL");
      if (eq != std::string::npos && !url_decode(pair.substr(eq + 1), true, value))
        return bad_input("parameter '" + name + "': bad percent-encoding or NUL");
      req.params.emplace_back(std::move(name), std::move(value));
    }
  }
  std::size_t pos = line_end == std::string::npos ? head.size() : line_end + 2;
  while (pos < head.size()) {
    auto end = head.find("\r\n", pos);
    if (end == std::string::npos) end = head.size();
    const std::string h = head.substr(pos, end - pos);
    pos = end + 2;
    const auto colon = h.find(':');
    if (colon == std::string::npos || colon == 0) return bad_input("malformed header line");
    const std::string name = to_lower(h.substr(0, colon));
    const std::string value = trimmed(h.substr(colon + 1));
    auto [it, fresh] = req.headers.emplace(name, value);
    if (!fresh) {
      static const std::unordered_set<std::string> single{
          "host", "content-length", "content-type", "origin", "x-csrf-token", "cookie", "transfer-encoding"};
      if (single.count(name) != 0) return bad_input("header '" + name + "' given twice");
      it->second += ", " + value;
    }
  }
  return req;
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
  bool want_out = false;
  std::int64_t accepted_ns = 0;
  std::int64_t request_start_ns = 0;  //!< [ns] first byte of the request being read (0: none yet)
  std::int64_t activity_ns = 0;       //!< [ns] last byte read or written
  std::size_t pending() const {
    return out.size() - out_off + (body ? body->size() - body_off : 0) + chunk_bytes - chunk_off;
  }
};

struct Job {
  std::uint64_t conn = 0;
  HttpRequest request;
  bool keep_alive = false;
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
  HttpServer* owner = nullptr;
  int listen_fd = -1;
  int epoll_fd = -1;
  int wake_fd = -1;
  SSL_CTX* ssl_ctx = nullptr;
  std::unordered_map<std::uint64_t, std::unique_ptr<Conn>> conns;
  std::unordered_set<std::uint64_t> streams;
  std::uint64_t next_id = 2;
  std::uint64_t cursor = 0;  //!< stream messages up to this id are in every stream's buffer
  std::int64_t broadcast_ns = 0;
  std::int64_t swept_ns = 0;
  std::atomic<bool> stopping{false};
  std::mutex mutex;
  std::condition_variable work;
  std::deque<Job> jobs;
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

  void drop(Conn& c) {
    if (c.state == Conn::State::kStream) {
      streams.erase(c.id);
      owner->streams_ = streams.size();
    }
    ::epoll_ctl(epoll_fd, EPOLL_CTL_DEL, c.fd, nullptr);
    close_socket(c);
    conns.erase(c.id);  // destroys c
  }

  void watch(Conn& c, bool out) {
    if (c.want_out == out) return;
    c.want_out = out;
    epoll_event ev{};
    ev.events = EPOLLIN | (out ? EPOLLOUT : 0U);
    ev.data.u64 = c.id;
    ::epoll_ctl(epoll_fd, EPOLL_CTL_MOD, c.fd, &ev);
  }

  //! >0 bytes; 0 closed by the peer; -1 would block; -2 error.
  static long read_some(Conn& c, char* buf, std::size_t n) {
    if (c.ssl != nullptr) {
      ERR_clear_error();
      const int r = SSL_read(c.ssl, buf, static_cast<int>(n));
      if (r > 0) return r;
      const int e = SSL_get_error(c.ssl, r);
      if (e == SSL_ERROR_WANT_READ || e == SSL_ERROR_WANT_WRITE) return -1;
      return e == SSL_ERROR_ZERO_RETURN ? 0 : -2;
    }
    const ssize_t r = ::recv(c.fd, buf, n, 0);
    if (r > 0) return static_cast<long>(r);
    if (r == 0) return 0;
    return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? -1 : -2;
  }
  static long write_some(Conn& c, const char* buf, std::size_t n) {
    if (c.ssl != nullptr) {
      ERR_clear_error();
      const int r = SSL_write(c.ssl, buf, static_cast<int>(std::min<std::size_t>(n, 1 << 20)));
      if (r > 0) return r;
      const int e = SSL_get_error(c.ssl, r);
      return e == SSL_ERROR_WANT_READ || e == SSL_ERROR_WANT_WRITE ? -1 : -2;
    }
    const ssize_t r = ::send(c.fd, buf, n, MSG_NOSIGNAL);
    if (r >= 0) return static_cast<long>(r);
    return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? -1 : -2;
  }

  void accept_all(std::int64_t now) {
    for (;;) {
      sockaddr_storage addr{};
      socklen_t len = sizeof addr;
      const int fd =
          ::accept4(listen_fd, reinterpret_cast<sockaddr*>(&addr), &len, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) return;
      if (conns.size() >= limits.max_connections) {
        ::close(fd);
        continue;
      }
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      auto c = std::make_unique<Conn>();
      c->id = next_id++;
      c->fd = fd;
      c->accepted_ns = c->activity_ns = now;
      char text[INET6_ADDRSTRLEN] = "?";
      if (addr.ss_family == AF_INET) {
        ::inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(&addr)->sin_addr, text, sizeof text);
      } else if (addr.ss_family == AF_INET6) {
        ::inet_ntop(AF_INET6, &reinterpret_cast<sockaddr_in6*>(&addr)->sin6_addr, text, sizeof text);
      }
      c->remote = text;
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
    const std::size_t cap = limits.max_head_bytes + limits.max_body_bytes + sizeof buf;
    for (;;) {
      const long r = read_some(c, buf, sizeof buf);
      if (r == -1) break;
      if (r <= 0) return drop(c);
      if (c.state == Conn::State::kStream) continue;  // a stream's client has nothing to say
      if (c.in.empty() && c.request_start_ns == 0) c.request_start_ns = now;
      c.in.append(buf, static_cast<std::size_t>(r));
      c.activity_ns = now;
      if (c.in.size() > cap) break;
    }
    if (c.state == Conn::State::kReading) parse(c, now);
  }

  void refuse(Conn& c, int status, const std::string& message) {
    HttpResponse res;
    res.status = status;
    res.body = "{\"error\":\"" + message + "\"}";
    respond(c, std::move(res), false);
  }

  void parse(Conn& c, std::int64_t now) {
    const auto head_end = c.in.find("\r\n\r\n");
    if (head_end == std::string::npos || head_end > limits.max_head_bytes) {
      if (c.in.size() > limits.max_head_bytes) refuse(c, 431, "request head longer than the limit");
      return;
    }
    std::string version;
    auto req = parse_head(c.in.substr(0, head_end), version);
    if (!req) return refuse(c, 400, req.error().message);
    if (!req->header("transfer-encoding").empty())
      return refuse(c, 501, "request bodies in chunks are not accepted: send Content-Length");
    std::size_t length = 0;
    const std::string cl = req->header("content-length");
    if (!cl.empty()) {
      if (cl.size() > 12 || cl.find_first_not_of("0123456789") != std::string::npos)
        return refuse(c, 400, "header 'content-length' is not a number");
      length = std::stoul(cl);
      if (length > limits.max_body_bytes)
        return refuse(c, 413, "body longer than " + std::to_string(limits.max_body_bytes) + " bytes");
    }
    if (c.in.size() < head_end + 4 + length) return;  // the body is still arriving
    req->body = c.in.substr(head_end + 4, length);
    c.in.erase(0, head_end + 4 + length);
    c.request_start_ns = c.in.empty() ? 0 : now;
    req->remote_addr = c.remote;
    req->tls = c.ssl != nullptr;
    const bool keep_alive = version == "HTTP/1.1" && to_lower(req->header("connection")) != "close";
    {
      const std::lock_guard lock(mutex);
      if (jobs.size() >= limits.max_queued) {
        // Answered below, outside the lock.
      } else {
        c.state = Conn::State::kWorking;
        jobs.push_back({c.id, std::move(req).value(), keep_alive});
        work.notify_one();
        return;
      }
    }
    refuse(c, 503, "busy: too many requests waiting");
  }

  static void add_common_headers(std::string& head) {
    head +=
        "X-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\n"
        "Content-Security-Policy: frame-ancestors 'none'\r\nReferrer-Policy: no-referrer\r\n";
  }

  void respond(Conn& c, HttpResponse res, bool keep_alive) {
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
    if (res.shared_body) {
      c.body = std::move(res.shared_body);
      c.body_off = 0;
    } else {
      c.out += res.body;
    }
    c.close_after = !keep_alive;
    c.state = Conn::State::kWriting;
    flush(c, io_now_ns());
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
      const long w = write_some(c, data, n);
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
    watch(c, pending);
    if (!pending && c.state == Conn::State::kWriting) {
      if (c.close_after) return drop(c);
      c.state = Conn::State::kReading;
      c.activity_ns = now;
      if (!c.in.empty()) parse(c, now);
    }
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
        drop(c);
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
    std::vector<std::uint64_t> expired;
    for (const auto& [id, c] : conns) {
      switch (c->state) {
        case Conn::State::kReading:
          if (c->request_start_ns != 0 && now - c->request_start_ns > to_ns(limits.request_timeout_s)) {
            spdlog::info("ground: request from {} not complete within {} s: closed", c->remote,
                         limits.request_timeout_s);
            expired.push_back(id);
          } else if (c->request_start_ns == 0 && now - c->activity_ns > to_ns(limits.idle_timeout_s)) {
            expired.push_back(id);
          } else if (c->ssl != nullptr && !SSL_is_init_finished(c->ssl) &&
                     now - c->accepted_ns > to_ns(limits.request_timeout_s)) {
            expired.push_back(id);
          }
          break;
        case Conn::State::kWriting:
        case Conn::State::kStream:
          if (c->pending() > 0 && now - c->activity_ns > to_ns(limits.write_timeout_s)) {
            spdlog::info("ground: {} reads nothing for {} s: closed", c->remote, limits.write_timeout_s);
            expired.push_back(id);
          }
          break;
        case Conn::State::kWorking:
          break;
      }
    }
    for (const auto id : expired) drop(*conns.at(id));
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
        if ((what & (EPOLLIN | EPOLLHUP | EPOLLERR)) != 0U) {
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

  void serve_requests() {
    for (;;) {
      Job job;
      {
        std::unique_lock lock(mutex);
        work.wait(lock, [&] { return stopping || !jobs.empty(); });
        if (stopping) return;
        job = std::move(jobs.front());
        jobs.pop_front();
      }
      HttpResponse res;
      try {
        res = handler(job.request);
      } catch (const std::exception& e) {
        spdlog::error("ground: {} {}: {}", job.request.method, job.request.path, e.what());
        res = HttpResponse{};
        res.status = 500;
        res.body = "{\"error\":\"internal error\"}";
      }
      {
        const std::lock_guard lock(mutex);
        done.push_back({job.conn, std::move(res), job.keep_alive});
      }
      wake();
    }
  }
};

HttpServer::HttpServer(Handler handler, StreamFeed feed, HttpLimits limits)
    : impl_(std::make_unique<Impl>()) {
  impl_->handler = std::move(handler);
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
    m.ssl_ctx = SSL_CTX_new(TLS_server_method());
    if (m.ssl_ctx == nullptr) return failure("TLS: cannot create a context");
    SSL_CTX_set_min_proto_version(m.ssl_ctx, TLS1_2_VERSION);
    SSL_CTX_set_mode(m.ssl_ctx, SSL_MODE_ENABLE_PARTIAL_WRITE | SSL_MODE_ACCEPT_MOVING_WRITE_BUFFER);
    if (SSL_CTX_use_certificate_chain_file(m.ssl_ctx, tls.cert.c_str()) != 1)
      return bad_input("--tls-cert " + tls.cert + ": not a readable PEM certificate");
    if (SSL_CTX_use_PrivateKey_file(m.ssl_ctx, tls.key.c_str(), SSL_FILETYPE_PEM) != 1)
      return bad_input("--tls-key " + tls.key + ": not a readable PEM private key");
    if (SSL_CTX_check_private_key(m.ssl_ctx) != 1)
      return bad_input("--tls-key " + tls.key + ": does not match the certificate of --tls-cert");
  }
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string where = host + ":" + std::to_string(port);
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || found == nullptr)
    return bad_input("--listen " + where + ": unknown host");
  for (addrinfo* a = found; a != nullptr && m.listen_fd < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) == 0 && ::listen(fd, 1024) == 0) {
      m.listen_fd = fd;
    } else {
      ::close(fd);
    }
  }
  ::freeaddrinfo(found);
  if (m.listen_fd < 0) return failure("--listen " + where + ": cannot bind");
  sockaddr_storage bound{};
  socklen_t len = sizeof bound;
  ::getsockname(m.listen_fd, reinterpret_cast<sockaddr*>(&bound), &len);
  port_ = ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                            : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
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
  for (int i = 0; i < m.limits.workers; ++i) m.workers.emplace_back([&m] { m.serve_requests(); });
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
  if (m.wake_fd >= 0) m.wake();
  if (m.io.joinable()) m.io.join();
  for (auto& w : m.workers) {
    if (w.joinable()) w.join();
  }
  m.workers.clear();
}

}  // namespace tetra::ground
