// The ingest loop: poll the source, parse, publish each sample at once, and keep a histogram of the
// read → written latency (1 µs bins up to 100 ms; longer ones in the last bin, the maximum kept exactly).
#include "tetra/ingest/ingest.hpp"

#include <poll.h>

#include <algorithm>
#include <array>
#include <vector>

#include "byte_source.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/topics.hpp"

namespace tetra::ingest {

namespace {

constexpr std::size_t kLatencyBins = 100'000;            // 1 µs each
constexpr std::int64_t kHeldGiveUp_ns = 30'000'000'000;  // [ns] longest a reader may hold a write back

class LatencyHistogram {
 public:
  LatencyHistogram() : bins_(kLatencyBins, 0) {}
  void add(std::int64_t ns) {
    const auto us = static_cast<std::size_t>(std::max<std::int64_t>(ns, 0) / 1000);
    ++bins_[std::min(us, kLatencyBins - 1)];
    ++count_;
    max_ns_ = std::max(max_ns_, ns);
  }
  double quantile_ms(double q) const {
    if (count_ == 0) return 0.0;
    const auto want = static_cast<std::uint64_t>(q * static_cast<double>(count_ - 1)) + 1;
    std::uint64_t seen = 0;
    for (std::size_t b = 0; b < kLatencyBins; ++b) {
      seen += bins_[b];
      if (seen >= want) return static_cast<double>(b + 1) * 1e-3;  // the bin's upper edge
    }
    return max_ms();
  }
  double max_ms() const { return static_cast<double>(max_ns_) * 1e-6; }

 private:
  std::vector<std::uint32_t> bins_;
  std::uint64_t count_ = 0;
  std::int64_t max_ns_ = 0;
};

Status wait_for_readers(const dds::Session& session, const dds::Writer<tetra_GyroSample>& writer,
                        const IngestOptions& o, dds::ShutdownSignal* shutdown) {
  const std::int64_t give_up = dds::monotonic_ns() + seconds_to_ns(o.wait_timeout_s);
  std::vector<std::intptr_t> fired;
  for (;;) {
    auto matched = writer.matched_readers();
    if (!matched) return matched.error();
    if (static_cast<int>(*matched) >= o.wait_readers) break;
    if (shutdown != nullptr && shutdown->requested()) return failure("interrupted while waiting for readers");
    if (dds::monotonic_ns() >= give_up) {
      return failure("only " + std::to_string(*matched) + " of " + std::to_string(o.wait_readers) +
                     " GyroSample readers appeared (is `tetra fusion` running on this domain?)");
    }
    if (auto s = session.wait(std::chrono::milliseconds(20), fired); !s) return s.error();
  }
  // A volatile reader hears only what is written after it discovered the writer: allow discovery to settle.
  if (o.wait_readers > 0) {
    if (auto s = session.wait(std::chrono::milliseconds(200), fired); !s) return s.error();
  }
  return ok_status();
}

}  // namespace

std::unique_ptr<SampleParser> line_protocol_parser(const IngestOptions& options) {
  return std::make_unique<LineProtocolParser>(options.gyro_count);
}

namespace {

//! The GyroSample writer: every sample kept until each reader has acknowledged it.
Result<dds::Writer<tetra_GyroSample>> gyro_writer(dds::Session& session, const IngestOptions& o) {
  dds::Qos qos = dds::gyro_sample_qos(std::chrono::nanoseconds(seconds_to_ns(1.0 / o.rate_hz)));
  qos.no_autodispose();
  // A source may deliver a burst (a serial buffer or a file read at once, faster than real time): every
  // sample kept until each reader has acknowledged it, as play's writer (history is not part of the
  // reader-writer contract: any reader still matches). A reader behind (a recorder paused) holds ingest
  // back, and the source waits in its own buffer (a pipe, a terminal) instead of samples being dropped.
  qos.keep_all();
  return session.writer<tetra_GyroSample>(qos);
}

//! Writes parsed samples, each held until the readers take it, counting them and their latency.
class SamplePublisher {
 public:
  SamplePublisher(dds::Writer<tetra_GyroSample>& writer, const IngestOptions& o,
                  dds::ShutdownSignal* shutdown)
      : writer_(writer), shutdown_(shutdown), seq_(static_cast<std::size_t>(o.gyro_count) + 1, 0) {}
  Status unit(const std::string& name) { return dds::copy_bounded(msg_.unit, name, "unit"); }
  //! Writes and clears `samples`, read from the source at `read_ns`.
  Status publish(std::vector<RawGyroSample>& samples, std::int64_t read_ns, IngestReport& report) {
    for (const RawGyroSample& s : samples) {
      msg_.gyro = static_cast<std::uint16_t>(s.gyro);
      msg_.seq = ++seq_[static_cast<std::size_t>(s.gyro)];
      msg_.stamp_ns = seconds_to_ns(s.time_s);
      msg_.raw = s.raw;
      msg_.flags = 0;
      auto held = writer_.write_held(msg_, std::chrono::nanoseconds(kHeldGiveUp_ns),
                                     [&] { return shutdown_ != nullptr && shutdown_->requested(); });
      if (!held) return held.error();
      if (*held == dds::Writer<tetra_GyroSample>::Held::stopped) break;  // interrupted: the loop ends
      if (*held == dds::Writer<tetra_GyroSample>::Held::timed_out) {
        return failure("a GyroSample reader has acknowledged nothing for 30 s: stopped at time " +
                       std::to_string(s.time_s) + " s of the source (every sample before it delivered)");
      }
      latency_.add(dds::monotonic_ns() - read_ns);
      ++report.samples;
    }
    samples.clear();
    return ok_status();
  }
  const LatencyHistogram& latency() const { return latency_; }

 private:
  dds::Writer<tetra_GyroSample>& writer_;
  dds::ShutdownSignal* shutdown_;
  tetra_GyroSample msg_{};
  std::vector<std::uint64_t> seq_;
  LatencyHistogram latency_;
};

//! The parser's counts into `report`.
void count_lines(const SampleParser& parser, IngestReport& report) {
  report.lines = parser.accepted();
  report.malformed = parser.malformed();
}

//! The report's closing figures: wall time since `start`, the parser's last problem, the latency quantiles.
void close_report(IngestReport& report, const SampleParser& parser, const LatencyHistogram& latency,
                  std::int64_t start) {
  report.wall_s = ns_to_seconds(dds::monotonic_ns() - start);
  count_lines(parser, report);
  report.last_problem = parser.last_problem();
  report.latency_p50_ms = latency.quantile_ms(0.5);
  report.latency_p99_ms = latency.quantile_ms(0.99);
  report.latency_max_ms = latency.max_ms();
}

}  // namespace

Result<IngestReport> run_ingest(const IngestOptions& o, dds::ShutdownSignal* shutdown,
                                const ParserFactory& make_parser,
                                const std::function<void(const IngestReport&)>& on_progress) {
  auto session = dds::Session::open(o.domain, o.unit);
  if (!session) return session.error();
  auto writer = gyro_writer(*session, o);
  if (!writer) return writer.error();
  auto source = ByteSource::open(o);
  if (!source) return source.error();
  if (Status s = wait_for_readers(*session, *writer, o, shutdown); !s) return s.error();
  auto parser = make_parser(o);
  SamplePublisher publisher(*writer, o, shutdown);
  if (auto s = publisher.unit(o.unit); !s) return s.error();
  std::vector<RawGyroSample> samples;
  std::array<std::uint8_t, 65536> buffer{};
  IngestReport report;
  const std::int64_t start = dds::monotonic_ns();
  const std::int64_t stop_at = o.duration_s > 0 ? start + seconds_to_ns(o.duration_s) : INT64_MAX;
  std::int64_t next_progress = start + 1'000'000'000;
  bool ended = false;
  while (!ended && (shutdown == nullptr || !shutdown->requested())) {
    const std::int64_t now = dds::monotonic_ns();
    if (now >= stop_at) break;
    pollfd pfd{(*source)->fd(), POLLIN, 0};
    const int ready =
        ::poll(&pfd, 1, static_cast<int>(std::min<std::int64_t>(100, (stop_at - now) / 1'000'000 + 1)));
    if (ready > 0) {
      auto got = (*source)->read(buffer, ended);
      if (!got) return got.error();
      const std::int64_t read_ns = dds::monotonic_ns();
      report.bytes += *got;
      parser->feed(std::span(buffer.data(), *got), samples);
      if ((*source)->datagrams() || ended) parser->flush(samples);
      if (auto st = publisher.publish(samples, read_ns, report); !st) return st.error();
      if (*got == 0 && !ended && (pfd.revents & POLLHUP) != 0) ended = true;
    }
    if (on_progress && dds::monotonic_ns() >= next_progress) {
      count_lines(*parser, report);
      on_progress(report);
      next_progress += 1'000'000'000;
    }
  }
  // What a reader has not acknowledged yet: waited for as a held write is (briefly when interrupted).
  const bool interrupted = shutdown != nullptr && shutdown->requested();
  (void)writer->wait_for_acks(std::chrono::nanoseconds(interrupted ? 2'000'000'000 : kHeldGiveUp_ns));
  close_report(report, *parser, publisher.latency(), start);
  return report;
}

}  // namespace tetra::ingest
