#pragma once
// The sockets of the ground's HTTP server (http_server.cpp) on Asio: the listening socket, the TLS
// context (OpenSSL under Asio's ssl::context).

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>
#include <optional>
#include <string>

#include "tetra/core/result.hpp"
#include "tetra/ground/http_server.hpp"

namespace tetra::ground::http_detail {

//! A TLS 1.2+ server context with the certificate chain and key into `out` (an input error when they
//! do not match).
Status make_tls_context(const TlsFiles& tls, std::optional<boost::asio::ssl::context>& out);
//! Opens, binds (port 0: any free port) and listens; `bound_port` the one bound.
Status listen_on(boost::asio::ip::tcp::acceptor& acceptor, const std::string& host, int port,
                 int& bound_port);

}  // namespace tetra::ground::http_detail
