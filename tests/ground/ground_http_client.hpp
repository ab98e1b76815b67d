#pragma once
// The ground station's HTTP server in process for tests (a fake command sender that acknowledges every
// command), and a raw-socket client: one request per connection, from any loopback address.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tetra/ground/http_api.hpp"

namespace tetra::ground::http_test {

using nlohmann::json;

//! A connection to 127.0.0.1:port from `from` (another loopback address stands for another client).
inline int connect_to(int port, const char* from = nullptr) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (from != nullptr) {
    sockaddr_in local{};
    local.sin_family = AF_INET;
    ::inet_pton(AF_INET, from, &local.sin_addr);
    if (::bind(fd, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0) {
      ::close(fd);
      return -1;
    }
  }
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{10, 0};  // a hang becomes a failure
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

//! Reads until the peer closes, `until` appears, or 10 s pass without data.
inline std::string read_from(int fd, const std::string& until = "") {
  std::string text;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (!until.empty() && text.find(until) != std::string::npos) break;
  }
  return text;
}

struct Reply {
  int status = 0;
  std::string head;
  std::string body;
  json data() const { return json::parse(body, nullptr, false); }
};

inline Reply parse_reply(const std::string& text) {
  Reply r;
  const auto end = text.find("\r\n\r\n");
  r.head = text.substr(0, end);
  r.body = end == std::string::npos ? "" : text.substr(end + 4);
  if (text.size() > 12) r.status = std::atoi(text.substr(9, 3).c_str());
  return r;
}

class Ground {
 public:
  explicit Ground(ServerConfig config) : store_(StoreConfig{}) {
    config.web_dir = std::string(TETRA_SOURCE_DIR) + "/web";
    config.port = 0;
    server_ = std::make_unique<GroundServer>(
        store_,
        [this](const CommandRequest& request) -> Result<dds::EventView> {
          sent.push_back(request);
          dds::EventView ack;
          ack.unit = request.unit;
          ack.command_id = 7;
          ack.command.operator_id = request.operator_id;
          ack.command.origin = request.origin;
          ack.event.type = fdi::EventType::kCommand;
          ack.event.detail = "done";
          return ack;
        },
        std::move(config));
  }
  Status start() { return server_->start(); }
  int port() const { return server_->port(); }
  std::string host() const { return "127.0.0.1:" + std::to_string(port()); }
  //! One request on its own connection; `headers` are whole lines with CRLF.
  Reply request(const std::string& method, const std::string& path, const std::string& headers = "",
                const std::string& body = "", const char* from = nullptr) const {
    const int fd = connect_to(port(), from);
    std::string req = method + " " + path + " HTTP/1.1\r\nHost: " + host() + "\r\nConnection: close\r\n" +
                      headers + "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
    (void)::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    Reply r = parse_reply(read_from(fd));
    ::close(fd);
    return r;
  }
  GroundStore& store() { return store_; }
  std::vector<CommandRequest> sent;

 private:
  GroundStore store_;
  std::unique_ptr<GroundServer> server_;
};

const std::string kJson = "Content-Type: application/json\r\n";

}  // namespace tetra::ground::http_test
