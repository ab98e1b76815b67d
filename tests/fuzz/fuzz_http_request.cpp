// libFuzzer target: the ground station's HTTP request parser (services/ground/src/http_parse.cpp:
// Boost.Beast's parser and the checks around it) on arbitrary bytes, as a connection delivers them.
// Never a crash or a hang; a request takes at most the bytes given and has a method, a path starting
// with '/' and a head and path of UTF-8 without control bytes; a refusal has a status of 400, 413, 431
// or 501 and a message whose JSON body parses; a prefix of the bytes is never read as another request
// than the whole (a proxy and this server cannot disagree).
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/ground/http_parse.hpp"

using tetra::ground::ParseOutcome;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const tetra::ground::ParseLimits limits{512U + data[0] * 16U, 1024};
  const std::string_view in(reinterpret_cast<const char*>(data + 1), size - 1);
  const ParseOutcome whole = tetra::ground::parse_request(in, limits);
  if (whole.kind == ParseOutcome::Kind::kRequest) {
    const auto& r = whole.request;
    TETRA_FUZZ_CHECK(whole.consumed <= in.size());
    TETRA_FUZZ_CHECK(!r.method.empty() && !r.path.empty() && r.path[0] == '/');
    TETRA_FUZZ_CHECK(tetra::ground::is_utf8(r.path));
    TETRA_FUZZ_CHECK(r.path.find_first_of(std::string_view("\0\r\n", 3)) == std::string::npos);
    TETRA_FUZZ_CHECK(r.body.size() <= limits.max_body_bytes);
    for (const auto& [name, value] : r.headers) {
      TETRA_FUZZ_CHECK(value.find_first_of("\r\n") == std::string::npos && tetra::ground::is_utf8(value));
      TETRA_FUZZ_CHECK(name.find_first_of(" \t:") == std::string::npos);
    }
    for (const auto& [name, value] : r.params) TETRA_FUZZ_CHECK(tetra::ground::is_utf8(name + value));
  } else if (whole.kind == ParseOutcome::Kind::kRefused) {
    TETRA_FUZZ_CHECK(whole.status == 400 || whole.status == 413 || whole.status == 431 ||
                     whole.status == 501);
    TETRA_FUZZ_CHECK(!whole.message.empty() && whole.message.find('\n') == std::string::npos);
    const auto body = nlohmann::json::parse(tetra::ground::error_body(whole.message), nullptr, false);
    TETRA_FUZZ_CHECK(body.is_object() && body.contains("error"));
  }
  // A prefix (the bytes arrived so far) is incomplete, the same request, or refused when the whole is.
  const std::size_t cut = data[0] % (in.size() + 1);
  const ParseOutcome part = tetra::ground::parse_request(in.substr(0, cut), limits);
  if (part.kind == ParseOutcome::Kind::kRequest) {
    TETRA_FUZZ_CHECK(whole.kind == ParseOutcome::Kind::kRequest && part.consumed == whole.consumed);
    TETRA_FUZZ_CHECK(part.request.path == whole.request.path && part.request.body == whole.request.body);
  } else if (part.kind == ParseOutcome::Kind::kRefused) {
    TETRA_FUZZ_CHECK(whole.kind == ParseOutcome::Kind::kRefused && part.status == whole.status);
  }
  return 0;
}
