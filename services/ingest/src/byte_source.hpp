#pragma once
// Where `tetra ingest` reads bytes: standard input, a UDP socket (each read one datagram) or a serial
// device set up with termios (raw, 8 data bits, 1 stop bit, the baud rate and parity asked for).

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "tetra/core/result.hpp"
#include "tetra/ingest/ingest.hpp"

namespace tetra::ingest {

class ByteSource {
 public:
  static Result<std::unique_ptr<ByteSource>> open(const IngestOptions& options);
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;
  ~ByteSource();
  int fd() const { return fd_; }                 //!< for poll()
  bool datagrams() const { return datagrams_; }  //!< each read is one whole datagram
  const std::string& name() const { return name_; }
  //! Reads what is there (never blocks once poll() said readable); `ended` at end of file or hang-up.
  Result<std::size_t> read(std::span<std::uint8_t> buffer, bool& ended);

 private:
  ByteSource() = default;
  int fd_ = -1;
  bool datagrams_ = false;
  std::string name_;
};

}  // namespace tetra::ingest
