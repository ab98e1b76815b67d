// tetra ingest — live gyro samples (the line protocol, core/sample_parser.hpp) from standard input, a UDP
// port or a serial device, published as GyroSample on DDS (docs/dds.md, "Ingesting live samples").
#include <iostream>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/ingest/ingest.hpp"

namespace tetra::cli {

namespace {

struct IngestCli {
  std::string parity = "none";
  bool quiet = false;
  ingest::IngestOptions options;
};

void add_ingest_options(CLI::App& app, IngestCli& o) {
  auto& io = o.options;
  auto* serial = app.add_option("--serial", io.serial_path, "read a serial device (or pseudo-terminal)");
  auto* udp = app.add_option("--udp", io.udp_port, "listen on this UDP port (one or more lines a datagram)")
                  ->check(CLI::Range(1, 65535));
  serial->excludes(udp);
  app.add_option("--udp-host", io.udp_host, "--udp: the IPv4 address to bind (default 0.0.0.0)");
  app.add_option("--baud", io.baud, "--serial: bits per second (9600 ... 921600)")
      ->check(CLI::PositiveNumber);
  app.add_option("--parity", o.parity, "--serial: none, even or odd (8 data bits, 1 stop bit)")
      ->check(CLI::IsMember({"none", "even", "odd"}));
  app.add_option("--gyros", io.gyro_count, "number of gyros N (ids 1..N)")
      ->check(CLI::Range(1, dds::kMaxGyrosOnWire));
  app.add_option("--rate-hz", io.rate_hz, "[Hz] the unit's sample rate (the deadline offered: 3 periods)")
      ->check(number_in(0.0, 1e5, true));
  app.add_option("--unit", io.unit, "the unit's key on the wire (default tetra-1)")->check(unit_name_check());
  app.add_option("--duration", io.duration_s, "[s] stop after this long (default: at the end of the source)")
      ->check(number_in(0.0, 1e9));
  app.add_option("--wait-readers", io.wait_readers,
                 "GyroSample readers to wait for before reading the source")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wait-timeout", io.wait_timeout_s, "[s] how long to wait for them")
      ->check(number_in(0.0, 86400.0, true));
  app.add_flag("-q,--quiet", o.quiet, "no progress lines on stderr");
  add_domain_option(app, io.domain);
}

}  // namespace

int cmd_ingest(int argc, char** argv) {
  CLI::App app{
      "Publish live gyro samples on DDS from a line protocol (TIME_S,GYRO,RAW or TIME_S,all,RAW1..RAWN) on "
      "standard "
      "input, a UDP port or a serial device; malformed lines are counted, never fatal (docs/dds.md)."};
  IngestCli o;
  add_ingest_options(app, o);
  if (auto code = parse(app, argc, argv)) return *code;
  o.options.parity = o.parity == "even"  ? ingest::Parity::kEven
                     : o.parity == "odd" ? ingest::Parity::kOdd
                                         : ingest::Parity::kNone;
  dds::ShutdownSignal shutdown;
  const auto progress = [&](const ingest::IngestReport& r) {
    if (o.quiet) return;
    std::cerr << "tetra ingest: " << r.lines << " lines, " << r.malformed << " malformed, " << r.samples
              << " samples published\n";
  };
  auto result = ingest::run_ingest(o.options, &shutdown, ingest::line_protocol_parser, progress);
  if (!result)
    return report("ingest", result.error(),
                  {{"baud", "--baud {value}: {message}"}, {"udp_host", "--udp-host {value}: {message}"}});
  const auto& r = *result;
  std::cout << "lines: " << r.lines << " accepted, " << r.malformed << " malformed";
  if (r.malformed > 0) std::cout << " (last: " << r.last_problem << ")";
  std::cout << "\nsamples published: " << r.samples << " in " << fixed(r.wall_s, 2) << " s (" << r.bytes
            << " bytes read)\n"
            << "latency read -> written [ms]: p50 " << fixed(r.latency_p50_ms, 3) << ", p99 "
            << fixed(r.latency_p99_ms, 3) << ", max " << fixed(r.latency_max_ms, 3) << '\n';
  return shutdown.requested() ? kExitFailure : kExitOk;
}

}  // namespace tetra::cli
