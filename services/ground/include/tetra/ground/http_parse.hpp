#pragma once
// The HTTP/1.1 request parser of the ground station's server (docs/ground.md, "Limits"): Boost.Beast's
// parser over the bytes received so far, with the checks it lacks around it; strict by design, so that
// no two readers of the same bytes (a proxy, this server) can see different requests. Every line ends
// in CRLF (a bare LF or CR is refused), a header name is a token followed at once by its colon
// (`Content-Length : N` is refused), no header is folded onto a following line, no control byte and no
// byte sequence that is not UTF-8 is anywhere in the head or the decoded path and parameters, a body is
// announced by a Content-Length of digits only (chunked bodies are refused). Pure: no I/O, no
// allocation beyond the parser's and the request's own, no exception; fuzzed by
// tests/fuzz/fuzz_http_request.cpp.

#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tetra::ground {

struct HttpRequest {
  std::string method;
  std::string path;                                         //!< decoded, without the query
  std::vector<std::pair<std::string, std::string>> params;  //!< decoded query parameters, in order
  std::map<std::string, std::string> headers;               //!< names in lower case
  std::string body;
  std::string remote_addr;
  bool tls = false;
  //! The header's value ("" when absent); `name` in lower case.
  std::string header(const std::string& name) const;
};

struct ParseLimits {
  std::size_t max_head_bytes = 16384;  //!< request line and headers; beyond: 431
  std::size_t max_body_bytes = 65536;  //!< beyond: 413 (from the Content-Length, before the body is read)
};

struct ParseOutcome {
  enum class Kind { kIncomplete, kRequest, kRefused };
  Kind kind = Kind::kIncomplete;
  HttpRequest request;       //!< kRequest
  bool keep_alive = false;   //!< kRequest: HTTP/1.1 without `Connection: close`
  std::size_t consumed = 0;  //!< kRequest: bytes of `in` the request took (head, blank line, body)
  int status = 0;            //!< kRefused: 400, 413, 431 or 501 (the connection is then closed)
  std::string message;       //!< kRefused: what is wrong, UTF-8, one line
};

//! The first request in `in` (bytes received so far on a connection).
ParseOutcome parse_request(std::string_view in, const ParseLimits& limits);

//! True when `text` is well-formed UTF-8 (no overlong form, no surrogate, at most U+10FFFF).
bool is_utf8(std::string_view text);

//! `{"error": message}` as JSON text, whatever the bytes of `message` (replaced when not UTF-8).
std::string error_body(const std::string& message);

//! The reason phrase of a status ("Status" for one not listed).
const char* reason_phrase(int status);

}  // namespace tetra::ground
