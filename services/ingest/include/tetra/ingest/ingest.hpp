#pragma once
// `tetra ingest`: live gyro samples from a byte source — standard input, a UDP port or a serial device —
// parsed by a SampleParser (the line protocol by default, tetra/core/sample_parser.hpp) and published as
// GyroSample on DDS (docs/dds.md, "Ingesting live samples"). Malformed input is counted, never fatal; a
// source that stalls publishes nothing, so the service's deadline sees its gyros absent.
// Latency stated: from the read() that delivered a sample's last byte to the return of its DDS write.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/core/sample_parser.hpp"

namespace tetra::dds {
class ShutdownSignal;
}

namespace tetra::ingest {

enum class Parity { kNone, kEven, kOdd };

struct IngestOptions {
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  std::string unit = "tetra-1";      //!< DDS key
  int gyro_count = 4;                //!< N: gyro ids 1..N
  double rate_hz = 100.0;            //!< [Hz] the unit's sample rate (the deadline offered: 3 periods)
  std::string serial_path;           //!< a serial device (or pseudo-terminal); "" = not serial
  int baud = 115200;                 //!< serial: bits per second
  Parity parity = Parity::kNone;     //!< serial: 8 data bits, 1 stop bit, this parity
  int udp_port = 0;                  //!< a UDP port to listen on (0 = not UDP); one or more lines a datagram
  std::string udp_host = "0.0.0.0";  //!< UDP: the address to bind
  double duration_s = 0.0;           //!< [s] stop after this long (0 = at the end of the source or a signal)
  int wait_readers = 1;              //!< GyroSample readers to wait for before reading the source
  double wait_timeout_s = 10.0;      //!< [s] give up waiting for them
};

struct IngestReport {
  std::uint64_t lines = 0;      //!< lines (frames) that gave samples
  std::uint64_t malformed = 0;  //!< lines (frames) refused
  std::string last_problem;     //!< why the last one was refused
  std::uint64_t samples = 0;    //!< GyroSample written
  std::uint64_t bytes = 0;      //!< bytes read from the source
  double wall_s = 0.0;          //!< [s] from the first read
  double latency_p50_ms = 0.0;  //!< [ms] read → written, median
  double latency_p99_ms = 0.0;  //!< [ms] 99th percentile
  double latency_max_ms = 0.0;  //!< [ms] worst
};

//! A parser for `options` (the line protocol for N gyros): the place a vendor's frame parser goes.
using ParserFactory = std::function<std::unique_ptr<SampleParser>(const IngestOptions&)>;
std::unique_ptr<SampleParser> line_protocol_parser(const IngestOptions& options);

//! Opens the source and publishes until it ends (standard input or serial: end of file or hang-up),
//! `duration_s` passes or a shutdown signal. `on_progress` about once per second.
Result<IngestReport> run_ingest(const IngestOptions& options, dds::ShutdownSignal* shutdown,
                                const ParserFactory& make_parser = line_protocol_parser,
                                const std::function<void(const IngestReport&)>& on_progress = {});

}  // namespace tetra::ingest
