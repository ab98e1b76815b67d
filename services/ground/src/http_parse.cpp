#include "tetra/ground/http_parse.hpp"

#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/string_body.hpp>
#include <nlohmann/json.hpp>
#include <unordered_set>

namespace tetra::ground {

namespace http = boost::beast::http;

std::string HttpRequest::header(const std::string& name) const {
  const auto it = headers.find(name);
  return it == headers.end() ? std::string() : it->second;
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
    case 429:
      return "Too Many Requests";
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

std::string error_body(const std::string& message) {
  return nlohmann::json{{"error", message}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

bool is_utf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto b = static_cast<unsigned char>(text[i]);
    if (b < 0x80) {
      ++i;
      continue;
    }
    std::size_t n = 0;
    unsigned cp = 0;
    unsigned min = 0;
    if ((b & 0xE0U) == 0xC0U) {
      n = 1, cp = b & 0x1FU, min = 0x80;
    } else if ((b & 0xF0U) == 0xE0U) {
      n = 2, cp = b & 0x0FU, min = 0x800;
    } else if ((b & 0xF8U) == 0xF0U) {
      n = 3, cp = b & 0x07U, min = 0x10000;
    } else {
      return false;
    }
    for (std::size_t k = 1; k <= n; ++k) {
      if (i + k >= text.size()) return false;
      const auto c = static_cast<unsigned char>(text[i + k]);
      if ((c & 0xC0U) != 0x80U) return false;
      cp = (cp << 6U) | (c & 0x3FU);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += n + 1;
  }
  return true;
}

namespace {

ParseOutcome refused(int status, std::string message) {
  ParseOutcome out;
  out.kind = ParseOutcome::Kind::kRefused;
  out.status = status;
  out.message = std::move(message);
  return out;
}

//! A control byte other than a tab (the only one a header value may hold).
bool has_control(std::string_view s) {
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\t') || c == 0x7F) return true;
  }
  return false;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& ch : out) {
    if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
  }
  return out;
}

int hex_digit(char h) {
  if (h >= '0' && h <= '9') return h - '0';
  if (h >= 'a' && h <= 'f') return h - 'a' + 10;
  if (h >= 'A' && h <= 'F') return h - 'A' + 10;
  return -1;
}

//! Percent-decoding (and '+' as space in a query); false on a bad escape, a NUL or bytes not UTF-8.
bool url_decode(std::string_view in, bool plus_is_space, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    char ch = in[i];
    if (ch == '%') {
      if (i + 2 >= in.size()) return false;
      const int hi = hex_digit(in[i + 1]);
      const int lo = hex_digit(in[i + 2]);
      if (hi < 0 || lo < 0) return false;
      ch = static_cast<char>(hi * 16 + lo);
      i += 2;
    } else if (ch == '+' && plus_is_space) {
      ch = ' ';
    }
    if (ch == '\0') return false;
    out += ch;
  }
  return is_utf8(out);
}

ParseOutcome parse_target(std::string_view target, HttpRequest& req) {
  if (target.empty() || target[0] != '/') return refused(400, "the request target must be a path");
  const auto q = target.find('?');
  if (!url_decode(target.substr(0, q), false, req.path))
    return refused(400, "path: bad percent-encoding, NUL or not UTF-8");
  if (has_control(req.path) || req.path.find('\t') != std::string::npos)
    return refused(400, "path: a control character");
  if (q == std::string_view::npos) return {};
  std::size_t start = q + 1;
  while (start <= target.size()) {
    auto amp = target.find('&', start);
    if (amp == std::string_view::npos) amp = target.size();
    const std::string_view pair = target.substr(start, amp - start);
    start = amp + 1;
    if (pair.empty()) continue;
    const auto eq = pair.find('=');
    std::string name;
    std::string value;
    if (!url_decode(pair.substr(0, eq), true, name))
      return refused(400, "query: bad percent-encoding, NUL or not UTF-8");
    if (eq != std::string_view::npos && !url_decode(pair.substr(eq + 1), true, value))
      return refused(400, "a query parameter: bad percent-encoding, NUL or not UTF-8");
    req.params.emplace_back(std::move(name), std::move(value));
  }
  return {};
}

//! True when a LF not preceded by CR comes before the head's end (or the end of `in`).
bool has_bare_lf(std::string_view in) {
  const std::size_t end = std::min(in.find("\r\n\r\n"), in.size());
  for (std::size_t i = in.find('\n'); i < end; i = in.find('\n', i + 1)) {
    if (i == 0 || in[i - 1] != '\r') return true;
  }
  return false;
}

//! The refusal for an error of Beast's parser: 431 and 413 for its limits, 400 for the rest.
ParseOutcome refused_by_parser(const boost::beast::error_code& ec) {
  if (ec == http::error::header_limit) return refused(431, "request head longer than the limit");
  if (ec == http::error::body_limit) return refused(413, "body longer than the limit");
  return refused(400, "malformed request: " + ec.message());
}

//! What Beast's parser lets through and this server does not: a header folded onto the next line
//! (Beast joins it), a version other than 1.0 and 1.1, a target that is not a path of printable ASCII,
//! header values not UTF-8, a header that counts once given twice, a body in chunks, a length that is a
//! list.
ParseOutcome check_head(std::string_view head, const http::request_parser<http::string_body>& parser,
                        HttpRequest& req) {
  for (std::size_t i = head.find("\r\n"); i != std::string_view::npos; i = head.find("\r\n", i + 2)) {
    if (i + 2 < head.size() && (head[i + 2] == ' ' || head[i + 2] == '\t'))
      return refused(400, "a header folded onto the next line (obs-fold)");
  }
  const auto& msg = parser.get();
  if (msg.version() != 11 && msg.version() != 10) return refused(400, "HTTP/1.0 or HTTP/1.1 only");
  req.method = std::string(msg.method_string());
  const std::string_view target = msg.target();
  for (const char ch : target) {
    const auto c = static_cast<unsigned char>(ch);
    if (c <= 0x20 || c >= 0x7F) return refused(400, "the request target holds a byte it may not");
  }
  if (auto t = parse_target(target, req); t.kind == ParseOutcome::Kind::kRefused) return t;
  static const std::unordered_set<std::string> single{
      "host",   "content-length",    "content-type", "origin",       "x-csrf-token",
      "cookie", "transfer-encoding", "connection",   "last-event-id"};
  for (const auto& field : msg) {
    const std::string name = lower(field.name_string());
    const std::string_view value = field.value();
    if (has_control(value) || !is_utf8(value))
      return refused(400, "header '" + name + "': a control character or bytes not UTF-8");
    auto [it, fresh] = req.headers.emplace(name, std::string(value));
    if (!fresh) {
      if (single.count(name) != 0) return refused(400, "header '" + name + "' given twice");
      it->second += ", ";
      it->second += value;
    }
  }
  if (req.headers.count("transfer-encoding") != 0)
    return refused(501, "request bodies in chunks are not accepted: send Content-Length");
  // Beast also takes a list of equal lengths ("5, 5"): one number, digits only.
  if (const auto cl = req.headers.find("content-length");
      cl != req.headers.end() && cl->second.find_first_not_of("0123456789") != std::string::npos)
    return refused(400, "header 'content-length' is not a number");
  return {};
}

}  // namespace

ParseOutcome parse_request(std::string_view in, const ParseLimits& limits) {
  // An empty line before the request line is ignored (RFC 9112 2.2).
  std::size_t start = 0;
  while (in.size() >= start + 2 && in.compare(start, 2, "\r\n") == 0) start += 2;
  if (start > 8) return refused(400, "empty lines before the request");
  if (in.size() == start + 1 && in[start] == '\r') return {};  // an empty line's CR, its LF to come
  http::request_parser<http::string_body> parser;
  parser.header_limit(static_cast<std::uint32_t>(std::min<std::size_t>(limits.max_head_bytes, UINT32_MAX)));
  parser.body_limit(limits.max_body_bytes);
  parser.eager(false);  // the head first, checked before any of the body is taken
  ParseOutcome out;
  std::size_t used = start;
  bool head_checked = false;
  while (!parser.is_done()) {
    boost::beast::error_code ec;
    const std::size_t n = parser.put(boost::asio::buffer(in.data() + used, in.size() - used), ec);
    used += n;
    if (ec && ec != http::error::need_more) return refused_by_parser(ec);
    if (parser.is_header_done() && !head_checked) {
      head_checked = true;
      if (auto h = check_head(in.substr(start, used - start), parser, out.request);
          h.kind == ParseOutcome::Kind::kRefused)
        return h;
      parser.eager(true);
    }
    if (!parser.is_done() && (n == 0 || used == in.size())) {
      // Beast reads a head only once it is whole: a bare LF (a line end to another reader) is refused
      // before, rather than waited on.
      if (!head_checked && has_bare_lf(in.substr(start))) return refused(400, "a line ends in LF without CR");
      return {};
    }
  }
  out.request.body = std::move(parser.get().body());
  out.consumed = used;
  out.keep_alive = parser.get().version() == 11 &&
                   lower(out.request.header("connection")).find("close") == std::string::npos;
  out.kind = ParseOutcome::Kind::kRequest;
  return out;
}

}  // namespace tetra::ground
