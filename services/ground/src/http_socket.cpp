#include "http_socket.hpp"

#include <openssl/ssl.h>

#include <boost/asio/ip/tcp.hpp>

namespace tetra::ground::http_detail {

namespace net = boost::asio;

Status make_tls_context(const TlsFiles& tls, std::optional<net::ssl::context>& out) {
  out.emplace(net::ssl::context::tls_server);
  SSL_CTX* ctx = out->native_handle();
  SSL_CTX_set_min_proto_version(ctx, TLS1_2_VERSION);  // TLS 1.0 and 1.1 refused
  std::string problem;
  if (SSL_CTX_use_certificate_chain_file(ctx, tls.cert.c_str()) != 1) {
    problem = "--tls-cert " + tls.cert + ": not a readable PEM certificate";
  } else if (SSL_CTX_use_PrivateKey_file(ctx, tls.key.c_str(), SSL_FILETYPE_PEM) != 1) {
    problem = "--tls-key " + tls.key + ": not a readable PEM private key";
  } else if (SSL_CTX_check_private_key(ctx) != 1) {
    problem = "--tls-key " + tls.key + ": does not match the certificate of --tls-cert";
  }
  if (problem.empty()) return ok_status();
  out.reset();
  return bad_input(problem);
}

Status listen_on(net::ip::tcp::acceptor& acceptor, const std::string& host, int port, int& bound_port) {
  const std::string where = host + ":" + std::to_string(port);
  boost::system::error_code ec;
  net::ip::tcp::resolver resolver(acceptor.get_executor());
  const auto found =
      resolver.resolve(host, std::to_string(port),
                       net::ip::resolver_base::passive | net::ip::resolver_base::numeric_service, ec);
  if (ec || found.empty()) return bad_input("--listen " + where + ": unknown host");
  for (const auto& entry : found) {
    acceptor.open(entry.endpoint().protocol(), ec);
    if (ec) continue;
    acceptor.set_option(net::socket_base::reuse_address(true), ec);
    acceptor.bind(entry.endpoint(), ec);
    if (!ec) acceptor.listen(1024, ec);
    if (!ec) {
      bound_port = acceptor.local_endpoint().port();
      return ok_status();
    }
    acceptor.close();
  }
  return failure("--listen " + where + ": cannot bind");
}

}  // namespace tetra::ground::http_detail
