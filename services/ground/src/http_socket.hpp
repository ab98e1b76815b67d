#pragma once
// The socket side of the ground's HTTP server (http_server.cpp): non-blocking reads and writes over
// TCP or TLS (OpenSSL), the listening socket, the TLS context, a peer's address as text.

#include <openssl/ssl.h>
#include <sys/socket.h>

#include <cstddef>
#include <string>

#include "tetra/core/result.hpp"
#include "tetra/ground/http_server.hpp"

namespace tetra::ground::http_detail {

//! >0 bytes; 0 closed by the peer; -1 would block; -2 error.
long read_some(int fd, SSL* ssl, char* buf, std::size_t n);
//! >0 bytes; -1 would block; -2 error.
long write_some(int fd, SSL* ssl, const char* buf, std::size_t n);
//! A TLS 1.2+ server context with the certificate chain and key (an input error when they do not match).
Result<SSL_CTX*> make_tls_context(const TlsFiles& tls);
//! A non-blocking listening socket bound to host:port (0: any free port); `bound_port` the one bound.
Result<int> listen_on(const std::string& host, int port, int& bound_port);
//! The numeric address of a peer ("?" when neither IPv4 nor IPv6).
std::string address_text(const sockaddr_storage& addr);

}  // namespace tetra::ground::http_detail
