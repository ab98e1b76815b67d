#include "tetra/ground/trusted_proxy.hpp"

#include <arpa/inet.h>

#include <algorithm>

namespace tetra::ground {

std::string canonical_address(const std::string& text) {
  char out[INET6_ADDRSTRLEN] = {};
  in_addr v4{};
  if (::inet_pton(AF_INET, text.c_str(), &v4) == 1)
    return ::inet_ntop(AF_INET, &v4, out, sizeof out) != nullptr ? out : "";
  in6_addr v6{};
  if (::inet_pton(AF_INET6, text.c_str(), &v6) != 1) return "";
  if (IN6_IS_ADDR_V4MAPPED(&v6)) {
    std::copy_n(v6.s6_addr + 12, 4, reinterpret_cast<unsigned char*>(&v4.s_addr));
    return ::inet_ntop(AF_INET, &v4, out, sizeof out) != nullptr ? out : "";
  }
  return ::inet_ntop(AF_INET6, &v6, out, sizeof out) != nullptr ? out : "";
}

Result<TrustedProxy> TrustedProxy::make(const std::string& header,
                                        const std::vector<std::string>& addresses) {
  TrustedProxy p;
  if (header.empty() && addresses.empty()) return p;
  if (header.empty() || addresses.empty())
    return bad_input("--trusted-proxy-header and --trusted-proxy go together");
  const bool token = std::all_of(header.begin(), header.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
  });
  if (!token || header.size() > 64)
    return bad_input("--trusted-proxy-header '" + header + "': a header name of letters, digits, - and _");
  for (const auto& a : addresses) {
    std::string canonical = canonical_address(a);
    if (canonical.empty())
      return bad_input("--trusted-proxy '" + a + "': not a numeric IPv4 or IPv6 address");
    p.addresses_.push_back(std::move(canonical));
  }
  p.header_ = header;
  std::transform(p.header_.begin(), p.header_.end(), p.header_.begin(),
                 [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
  return p;
}

bool TrustedProxy::trusts(const std::string& remote) const {
  const std::string canonical = canonical_address(remote);
  return !canonical.empty() && std::find(addresses_.begin(), addresses_.end(), canonical) != addresses_.end();
}

}  // namespace tetra::ground
