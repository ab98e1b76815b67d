#pragma once
// Sign-in through a reverse proxy (docs/ground.md, "Sign-in by the proxy"): a site's nginx authenticates
// the operator (LDAP, OIDC, client certificates) and names them in a header; the ground takes that
// header only from the proxy's own addresses, and the user still needs an account (a role) in the
// --users file. Off unless both the header and at least one address are given.

#include <string>
#include <vector>

#include "tetra/core/result.hpp"

namespace tetra::ground {

class TrustedProxy {
 public:
  TrustedProxy() = default;
  //! `header` a header name (a token), `addresses` numeric IPv4 or IPv6 addresses; both empty: off.
  static Result<TrustedProxy> make(const std::string& header, const std::vector<std::string>& addresses);
  bool enabled() const { return !header_.empty(); }
  //! The header's name in lower case (as HttpRequest keeps them).
  const std::string& header() const { return header_; }
  //! True when `remote` (a peer's numeric address, IPv4-mapped or not) is one of the proxy's.
  bool trusts(const std::string& remote) const;

 private:
  std::string header_;
  std::vector<std::string> addresses_;  //!< canonical text
};

//! The canonical text of a numeric address (IPv4-mapped IPv6 as IPv4); "" when not an address.
std::string canonical_address(const std::string& text);

}  // namespace tetra::ground
