// Plays a gyro log on DDS: the epochs of [start, end], paced by their times or in lockstep, once or looped.
// Looping: pass p publishes the times shifted by p × (span + one median period), so the stamps keep
// increasing and the service sees one continuous recording.
#include "tetra/player/log_player.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/player/player_link.hpp"
#include "tetra/service/unit_name.hpp"

namespace tetra::player {

namespace {

// What the first pass learns of the log before anything is published.
struct LogShape {
  GyroLog header;
  double rate_hz = 0.0;      // [Hz] from the median period of the first block
  double period_s = 0.0;     // [s] that median period
  double first_s = 0.0;      // [s] first time in [start, end]
  double last_s = 0.0;       // [s] last time in [start, end]
  std::uint64_t epochs = 0;  // epochs in [start, end]
};

//! [s] the longest step between two epochs played: a row far ahead of the rest (a damaged time) would
//! have play sleep through it (1e6 s ahead at speed 10: 28 hours).
constexpr double kMaxPlayStep_s = 3600.0;
//! Lockstep: epochs between two waits for every reader's acknowledgement (well under the 128 attitudes
//! the service's writer keeps for a reader behind).
constexpr std::uint64_t kAckEvery = 32;

bool in_window(double t, const PlayOptions& o) {
  return (!o.start_s || t >= *o.start_s) && (!o.end_s || t <= *o.end_s);
}

// One pass over the log without publishing: its header, rate, span and epochs in the window.
Result<LogShape> inspect(const std::string& path, const PlayOptions& options) {
  auto opened = GyroLogReader::open(path);
  if (!opened) return opened.error();
  GyroLogReader& reader = **opened;
  LogShape shape;
  shape.header = reader.header();
  if (shape.header.units_dps) {
    return bad_input(path +
                     ": the log holds rates (units=dps); GyroSample carries the gyros' raw outputs [V]: "
                     "play a log in volts (as tetra record writes it)");
  }
  GyroLog block;
  std::vector<double> periods;
  while (true) {
    auto more = reader.next(block);
    if (!more) return more.error();
    if (!*more) break;
    for (std::size_t k = 0; k < block.epochs(); ++k) {
      const double t = block.time_s[k];
      if (!in_window(t, options)) continue;
      if (shape.epochs == 0) shape.first_s = t;
      if (shape.epochs > 0 && t - shape.last_s > kMaxPlayStep_s) {
        std::string where = path;
        if (k < block.lines.size()) where += ":" + std::to_string(block.lines[k]);
        std::string times;
        append_double(times, t);
        times += " s is ";
        append_double(times, t - shape.last_s);
        return bad_input(where + ": time " + times +
                         " s after the epoch before it (more than 3600 s, which play would wait through): "
                         "play the parts on either side with --start/--end");
      }
      if (shape.epochs > 0 && periods.size() < 1000 && t > shape.last_s) periods.push_back(t - shape.last_s);
      shape.last_s = t;
      ++shape.epochs;
    }
  }
  if (shape.epochs == 0) return bad_input(path + ": no epoch within --start/--end");
  if (periods.empty()) periods.push_back(0.01);
  std::nth_element(periods.begin(), periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2),
                   periods.end());
  shape.period_s = periods[periods.size() / 2];
  shape.rate_hz = 1.0 / shape.period_s;
  return shape;
}

class Player {
 public:
  Player(PlayerLink& link, const LogShape& shape, const PlayOptions& options, PlayReport& report,
         const std::function<void(const PlayReport&)>& on_progress)
      : link_(link), shape_(shape), options_(options), report_(report), on_progress_(on_progress) {}

  // One pass; `offset_ns` shifts its stamps.
  Status pass(const std::string& path, std::int64_t offset_ns) {
    auto opened = GyroLogReader::open(path);
    if (!opened) return opened.error();
    GyroLog block;
    const auto n = static_cast<std::size_t>(shape_.header.gyro_count);
    while (!link_.stop_requested()) {
      auto more = (*opened)->next(block);
      if (!more) return more.error();
      if (!*more) break;
      for (std::size_t k = 0; k < block.epochs() && !link_.stop_requested(); ++k) {
        if (!in_window(block.time_s[k], options_)) continue;
        std::optional<std::array<double, 4>> ref;
        if (block.has_reference && block.reference_present[k] != 0) ref = block.reference_wxyz[k];
        const std::int64_t stamp = seconds_to_ns(block.time_s[k]) + offset_ns;
        if (Status s = epoch(stamp, std::span(block.values).subspan(k * n, n),
                             std::span(block.present).subspan(k * n, n), ref);
            !s)
          return s;
        report_.last_time_s = block.time_s[k];
      }
    }
    return ok_status();
  }

 private:
  Status epoch(std::int64_t stamp, std::span<const double> raw, std::span<const std::uint8_t> present,
               const std::optional<std::array<double, 4>>& ref) {
    const bool lockstep = options_.speed <= 0.0;
    if (!start_wall_) {
      start_wall_ = dds::monotonic_ns();
      first_stamp_ = stamp;
      next_progress_ = *start_wall_ + 1'000'000'000;
    }
    if (!lockstep) {
      const auto due = *start_wall_ +
                       static_cast<std::int64_t>(static_cast<double>(stamp - first_stamp_) / options_.speed);
      for (std::int64_t now = dds::monotonic_ns(); now < due && !link_.stop_requested();
           now = dds::monotonic_ns()) {
        if (Status s = link_.wait_until(due); !s) return s;
        if (Status s = link_.take_attitudes(report_.attitudes, newest_); !s) return s;
      }
      report_.worst_lag_ms =
          std::max(report_.worst_lag_ms, static_cast<double>(dds::monotonic_ns() - due) * 1e-6);
    }
    if (Status s = link_.publish(stamp, ++seq_, raw, present, ref, lockstep, report_.samples); !s) return s;
    // Lockstep waits for the service; every kAckEvery epochs also for every other reader (a recorder),
    // so none falls further behind than the service's Attitude writer keeps (kAttitudeWriterDepth).
    if (lockstep && seq_ % kAckEvery == 0) link_.wait_for_acks();
    report_.references += ref ? 1 : 0;
    ++report_.epochs;
    if (lockstep) {
      auto came = link_.wait_for_stamp(stamp, seconds_to_ns(options_.lockstep_timeout_s), newest_,
                                       [&](const fdi::AttitudeEstimate&) { ++report_.attitudes; });
      if (!came) return came.error();
      if (!*came) ++report_.lockstep_missing;
    } else if (Status s = link_.take_attitudes(report_.attitudes, newest_); !s) {
      return s;
    }
    if (on_progress_ && dds::monotonic_ns() >= next_progress_) {
      report_.wall_s = ns_to_seconds(dds::monotonic_ns() - *start_wall_);
      on_progress_(report_);
      next_progress_ += 1'000'000'000;
    }
    return ok_status();
  }

  PlayerLink& link_;
  const LogShape& shape_;
  const PlayOptions& options_;
  PlayReport& report_;
  const std::function<void(const PlayReport&)>& on_progress_;
  std::optional<std::int64_t> start_wall_;
  std::int64_t first_stamp_ = 0;
  std::int64_t next_progress_ = 0;
  std::int64_t newest_ = std::numeric_limits<std::int64_t>::min();
  std::uint64_t seq_ = 0;
};

}  // namespace

Result<PlayReport> play_log(const std::string& path, const PlayOptions& options,
                            dds::ShutdownSignal* shutdown,
                            const std::function<void(const PlayReport&)>& on_progress) {
  auto shape = inspect(path, options);
  if (!shape) return shape.error();
  PlayReport report;
  report.unit = !options.unit.empty() ? options.unit : shape->header.meta("unit").value_or("tetra-1");
  // The log's name for its unit becomes the key of every sample: one fusion and --unit accept, or none.
  if (options.unit.empty()) {
    if (Status s = service::check_unit_name(report.unit, path + ": the unit name of '# unit='"); !s)
      return s.error();
  }
  report.first_time_s = shape->first_s;
  auto link = PlayerLink::open(report.unit, shape->rate_hz, shape->header.has_reference, options, shutdown);
  if (!link) return link.error();
  Player player(**link, *shape, options, report, on_progress);
  const std::int64_t pass_span_ns = seconds_to_ns(shape->last_s - shape->first_s + shape->period_s);
  const std::int64_t start = dds::monotonic_ns();
  do {
    if (Status s = player.pass(path, static_cast<std::int64_t>(report.passes) * pass_span_ns); !s)
      return s.error();
    ++report.passes;
  } while (options.loop && !(*link)->stop_requested());
  report.wall_s = ns_to_seconds(dds::monotonic_ns() - start);
  (*link)->wait_for_acks();
  return report;
}

}  // namespace tetra::player
