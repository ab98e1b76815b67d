#include "tetra/ground/http_parse.hpp"

#include <nlohmann/json.hpp>
#include <unordered_set>

namespace tetra::ground {

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

bool is_token_char(char ch) {
  const auto c = static_cast<unsigned char>(ch);
  if (c >= 0x80 || c <= 0x20 || c == 0x7F) return false;
  static constexpr std::string_view kSeparators = "\"(),/:;<=>?@[\\]{}";
  return kSeparators.find(ch) == std::string_view::npos;
}

bool is_token(std::string_view s) {
  if (s.empty()) return false;
  for (const char ch : s) {
    if (!is_token_char(ch)) return false;
  }
  return true;
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

std::string_view trim_ows(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
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

//! Where the head ends (the index past its blank line), 0 while it has not arrived; a refusal for a
//! bare LF or CR, or a head longer than the limit.
ParseOutcome find_head_end(std::string_view in, std::size_t start, std::size_t max_head, std::size_t& end) {
  end = 0;
  const std::size_t scan = std::min(in.size(), start + max_head + 4);
  for (std::size_t i = start; i < scan; ++i) {
    if (in[i] == '\n' && (i == start || in[i - 1] != '\r'))
      return refused(400, "a line ends in LF without CR");
    if (in[i] == '\r' && i + 1 < in.size() && in[i + 1] != '\n')
      return refused(400, "a CR not followed by LF");
    if (in[i] == '\n' && i >= start + 3 && in.compare(i - 3, 4, "\r\n\r\n") == 0) {
      end = i + 1;
      if (end - start - 4 > max_head) break;
      return {};
    }
  }
  if (end != 0 || scan - start > max_head) return refused(431, "request head longer than the limit");
  return {};
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

}  // namespace

ParseOutcome parse_request(std::string_view in, const ParseLimits& limits) {
  // An empty line before the request line is ignored (RFC 9112 2.2).
  std::size_t start = 0;
  while (in.size() >= start + 2 && in.compare(start, 2, "\r\n") == 0) start += 2;
  if (start > 8) return refused(400, "empty lines before the request");
  std::size_t end = 0;
  if (auto found = find_head_end(in, start, limits.max_head_bytes, end);
      found.kind == ParseOutcome::Kind::kRefused || end == 0)
    return found;
  const std::string_view head = in.substr(start, end - start - 4);
  ParseOutcome out;
  HttpRequest& req = out.request;
  const auto line_end = head.find("\r\n");
  const std::string_view line = head.substr(0, line_end);
  const auto sp1 = line.find(' ');
  const auto sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos || line.find(' ', sp2 + 1) != std::string_view::npos)
    return refused(400, "malformed request line: METHOD SP TARGET SP VERSION");
  req.method = std::string(line.substr(0, sp1));
  if (!is_token(req.method)) return refused(400, "malformed request line: the method is not a token");
  const std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string_view version = line.substr(sp2 + 1);
  if (version != "HTTP/1.1" && version != "HTTP/1.0") return refused(400, "HTTP/1.0 or HTTP/1.1 only");
  for (const char ch : target) {
    const auto c = static_cast<unsigned char>(ch);
    if (c <= 0x20 || c >= 0x7F) return refused(400, "the request target holds a byte it may not");
  }
  if (auto t = parse_target(target, req); t.kind == ParseOutcome::Kind::kRefused) return t;
  static const std::unordered_set<std::string> single{
      "host",   "content-length",    "content-type", "origin",       "x-csrf-token",
      "cookie", "transfer-encoding", "connection",   "last-event-id"};
  std::size_t pos = line_end == std::string_view::npos ? head.size() : line_end + 2;
  while (pos < head.size()) {
    auto next = head.find("\r\n", pos);
    if (next == std::string_view::npos) next = head.size();
    const std::string_view h = head.substr(pos, next - pos);
    pos = next + 2;
    if (!h.empty() && (h[0] == ' ' || h[0] == '\t'))
      return refused(400, "a header folded onto the next line (obs-fold)");
    const auto colon = h.find(':');
    if (colon == std::string_view::npos || !is_token(h.substr(0, colon)))
      return refused(400, "malformed header line: a token name followed at once by ':'");
    const std::string name = lower(h.substr(0, colon));
    const std::string_view value = trim_ows(h.substr(colon + 1));
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
  std::size_t length = 0;
  if (const auto cl = req.headers.find("content-length"); cl != req.headers.end()) {
    if (cl->second.empty() || cl->second.size() > 12 ||
        cl->second.find_first_not_of("0123456789") != std::string::npos)
      return refused(400, "header 'content-length' is not a number");
    length = std::stoul(cl->second);
    if (length > limits.max_body_bytes)
      return refused(413, "body longer than " + std::to_string(limits.max_body_bytes) + " bytes");
  }
  if (in.size() < end + length) return {};  // the body is still arriving
  req.body = std::string(in.substr(end, length));
  out.consumed = end + length;
  out.keep_alive =
      version == "HTTP/1.1" && lower(req.header("connection")).find("close") == std::string::npos;
  out.kind = ParseOutcome::Kind::kRequest;
  return out;
}

}  // namespace tetra::ground
