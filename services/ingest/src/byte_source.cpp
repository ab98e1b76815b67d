#include "byte_source.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace tetra::ingest {

namespace {

Result<speed_t> baud_constant(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      return bad_input(ErrorSubject("baud", std::to_string(baud)),
                       "not a standard rate (9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600)");
  }
}

Status configure_serial(int fd, const IngestOptions& o) {
  auto speed = baud_constant(o.baud);
  if (!speed) return speed.error();
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0)
    return bad_input(o.serial_path + ": not a terminal: " + std::strerror(errno));
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | PARODD | CSIZE);
  tio.c_cflag |= CS8;
  if (o.parity != Parity::kNone) {
    tio.c_cflag |= PARENB;
    if (o.parity == Parity::kOdd) tio.c_cflag |= PARODD;
    tio.c_iflag |=
        INPCK | IGNPAR;  // check parity; a byte with a parity error is dropped (its line is malformed)
  }
  tio.c_cc[VMIN] = 1;
  tio.c_cc[VTIME] = 0;
  if (::cfsetispeed(&tio, *speed) != 0 || ::cfsetospeed(&tio, *speed) != 0 ||
      ::tcsetattr(fd, TCSANOW, &tio) != 0) {
    return failure(o.serial_path + ": cannot set " + std::to_string(o.baud) +
                   " baud: " + std::strerror(errno));
  }
  return ok_status();
}

}  // namespace

ByteSource::~ByteSource() {
  if (fd_ > 0) ::close(fd_);  // standard input (0) stays open
}

Result<std::unique_ptr<ByteSource>> ByteSource::open(const IngestOptions& o) {
  auto source = std::unique_ptr<ByteSource>(new ByteSource());
  if (!o.serial_path.empty()) {
    source->name_ = o.serial_path;
    source->fd_ = ::open(o.serial_path.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (source->fd_ < 0) return bad_input(o.serial_path + ": cannot open: " + std::strerror(errno));
    if (Status s = configure_serial(source->fd_, o); !s) return s.error();
  } else if (o.udp_port > 0) {
    source->name_ = "udp " + o.udp_host + ":" + std::to_string(o.udp_port);
    source->datagrams_ = true;
    source->fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (source->fd_ < 0) return failure(source->name_ + ": socket: " + std::strerror(errno));
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(o.udp_port));
    if (::inet_pton(AF_INET, o.udp_host.c_str(), &addr.sin_addr) != 1) {
      return bad_input(ErrorSubject("udp_host", o.udp_host), "not an IPv4 address");
    }
    if (::bind(source->fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      return failure(source->name_ + ": cannot bind: " + std::strerror(errno));
    }
  } else {
    source->name_ = "standard input";
    source->fd_ = 0;
  }
  return source;
}

Result<std::size_t> ByteSource::read(std::span<std::uint8_t> buffer, bool& ended) {
  ended = false;
  const ssize_t got = ::read(fd_, buffer.data(), buffer.size());
  if (got > 0) return static_cast<std::size_t>(got);
  if (got == 0 && !datagrams_) {
    ended = true;  // end of file
    return std::size_t{0};
  }
  if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return std::size_t{0};
  if (got < 0 && errno == EIO && !datagrams_) {
    ended = true;  // a terminal hung up (the other end of a pseudo-terminal closed)
    return std::size_t{0};
  }
  if (got == 0) return std::size_t{0};
  return failure(name_ + ": read error: " + std::strerror(errno));
}

}  // namespace tetra::ingest
