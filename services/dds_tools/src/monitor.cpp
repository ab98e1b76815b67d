// Ground monitoring over DDS (tetra/dds_tools/monitor.hpp).
#include "tetra/dds_tools/monitor.hpp"

#include <algorithm>
#include <cstdio>
#include <deque>
#include <limits>
#include <map>
#include <sstream>
#include <vector>

#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/ground/encode.hpp"
#include "tetra/ground/ground_readers.hpp"
#include "tetra/ground/link_state.hpp"
#include "tetra/report/text.hpp"

namespace tetra::dds_tools {

namespace {

using dds::monotonic_ns;
using report::fixed;
using report::json_number;
using report::json_string;

constexpr std::size_t kRecentEvents = 8;  // shown per unit on the dashboard

struct UnitView {
  std::optional<dds::HealthView> health;
  std::optional<fdi::AttitudeEstimate> attitude;
  std::uint64_t attitudes_received = 0;
  std::uint64_t attitudes_at_last_refresh = 0;
  double attitude_rate_hz = 0.0;      //!< [Hz] measured between refreshes
  std::deque<dds::EventView> events;  //!< the most recent events (for the dashboard)
  std::uint64_t max_event_seq = 0;
  std::optional<std::int64_t> health_received_ns;    //!< [ns] monotonic
  std::optional<std::int64_t> attitude_received_ns;  //!< [ns] monotonic
  bool writer_alive = true;                          //!< the service's Health writer is alive
  ground::Link link = ground::Link::kWaiting;
};

//! "age 0.4 s" of a value received at `received_ns`, or "none".
std::string age_text(const std::optional<std::int64_t>& received_ns, std::int64_t now_ns) {
  return received_ns ? report::fixed(ns_to_seconds(now_ns - *received_ns), 1) + " s" : std::string("none");
}

void update_link(UnitView& view, std::int64_t now_ns) {
  const auto age = view.health_received_ns ? std::optional(now_ns - *view.health_received_ns) : std::nullopt;
  view.link = ground::link_state(age, view.health ? view.health->health_period_s : 0.0, view.writer_alive);
}

//! A value of the parity space, or "not available" (fewer than four gyros: no parity space).
std::string parity_text(const fdi::Health& h, double value) {
  return ground::parity_available(h) ? fixed(value, 2) : std::string("not available");
}

std::string event_json(const dds::EventView& e, int n_gyros) {
  // The docs/interfaces.md §2.5 object, with the unit, sequence number and command id added in front.
  std::string body = fdi::to_json(e.event, n_gyros);
  std::string head = "{\"type\": \"event\", \"unit\": " + json_string(e.unit) +
                     ", \"event_seq\": " + std::to_string(e.event_seq);
  if (e.command_id != 0) head += ", \"command_id\": " + std::to_string(e.command_id);
  return head + (body.size() > 2 ? ", " + body.substr(1) : "}");
}

std::string health_json(const std::string& unit, const UnitView& view, std::int64_t now_ns) {
  std::ostringstream out;
  const auto age = [&](const std::optional<std::int64_t>& received) {
    return received ? json_number(ns_to_seconds(now_ns - *received)) : std::string("null");
  };
  out << "{\"type\": \"health\", \"unit\": " << json_string(unit) << ", \"link\": \""
      << ground::to_string(view.link) << "\", \"health_age_s\": " << age(view.health_received_ns)
      << ", \"attitude_age_s\": " << age(view.attitude_received_ns);
  if (view.health) {
    const fdi::Health& h = view.health->health;
    const int n = static_cast<int>(h.gyros.size());
    const auto& c = view.health->counters;
    out << ", \"time_s\": " << json_number(ns_to_seconds(h.stamp_ns)) << ", \"mode\": \""
        << fdi::to_string(h.mode) << "\", \"gyros_used\": \"" << mask_to_string(h.used, n)
        << "\", \"gyros\": [";
    for (int i = 0; i < n; ++i) {
      out << (i ? ", " : "") << "{\"id\": " << i + 1 << ", \"state\": \""
          << fdi::to_string(h.gyros[static_cast<std::size_t>(i)].state) << "\", \"kind\": \""
          << fdi::to_string(h.gyros[static_cast<std::size_t>(i)].kind) << "\"}";
    }
    // Fewer than four gyros: no parity space, the parity fields are null ("not available").
    const double na = std::numeric_limits<double>::quiet_NaN();
    const bool parity = ground::parity_available(h);
    out << "], \"parity_available\": " << (parity ? "true" : "false")
        << ", \"parity_residual\": " << json_number(parity ? h.parity_residual : na)
        << ", \"chi2\": " << json_number(parity ? h.chi2 : na)
        << ", \"chi2_threshold\": " << json_number(h.chi2_threshold)
        << ", \"cusum\": " << json_number(parity ? h.cusum : na)
        << ", \"cusum_threshold\": " << json_number(h.cusum_threshold) << ", \"counters\": {"
        << "\"epochs_accepted\": " << h.counters.epochs_accepted
        << ", \"epochs_rejected_time\": " << h.counters.epochs_rejected_time
        << ", \"samples_accepted\": " << h.counters.samples_accepted
        << ", \"samples_invalid\": " << h.counters.samples_invalid
        << ", \"samples_absent\": " << h.counters.samples_absent << ", \"samples_late\": " << c.samples_late
        << ", \"samples_duplicate\": " << c.samples_duplicate
        << ", \"samples_out_of_order\": " << c.samples_out_of_order << ", \"samples_gap\": " << c.samples_gap
        << ", \"samples_unknown_gyro\": " << c.samples_unknown_gyro
        << ", \"samples_other_unit\": " << c.samples_other_unit
        << ", \"deadlines_missed\": " << c.deadlines_missed << ", \"liveliness_lost\": " << c.liveliness_lost
        << ", \"sensor_restarts\": " << c.sensor_restarts << ", \"time_outlier\": " << c.time_outlier
        << ", \"seq_discontinuity\": " << c.seq_discontinuity << ", \"unit_silences\": " << c.unit_silences
        << "}, \"events_published\": " << view.health->events_published;
  }
  if (view.attitude) {
    const auto& a = *view.attitude;
    const auto q = to_wxyz(a.q_RB);
    out << ", \"attitude\": {\"time_s\": " << json_number(ns_to_seconds(a.stamp_ns)) << ", \"q\": ["
        << json_number(q[0]) << ", " << json_number(q[1]) << ", " << json_number(q[2]) << ", "
        << json_number(q[3]) << "], \"rate_dps\": [" << json_number(a.omega_BR_B_rad_s.x() * kRadToDeg)
        << ", " << json_number(a.omega_BR_B_rad_s.y() * kRadToDeg) << ", "
        << json_number(a.omega_BR_B_rad_s.z() * kRadToDeg)
        << "], \"sigma_deg\": " << json_number(a.sigma_rad.maxCoeff() * kRadToDeg) << ", \"mode\": \""
        << fdi::to_string(a.mode) << "\", \"rate_hz\": " << json_number(view.attitude_rate_hz) << "}";
  }
  out << "}";
  return out.str();
}

std::string dashboard_block(const std::string& unit, const UnitView& view, std::int64_t now_ns) {
  std::ostringstream out;
  out << "unit " << unit;
  if (!view.health) return out.str() + "   (no health yet)\n";
  if (view.link != ground::Link::kLive) {
    out << "   *** " << ground::to_string(view.link) << " *** (what follows is the last health received)";
  }
  out << "   health age " << age_text(view.health_received_ns, now_ns) << ", attitude age "
      << age_text(view.attitude_received_ns, now_ns) << '\n';
  const fdi::Health& h = view.health->health;
  const int n = static_cast<int>(h.gyros.size());
  const auto& c = view.health->counters;
  out << "   mode " << fdi::to_string(h.mode) << "   gyros " << mask_to_string(h.used, n)
      << "   t = " << fixed(ns_to_seconds(h.stamp_ns), 3) << " s\n";
  out << "  gyro  state     fault\n";
  for (int i = 0; i < n; ++i) {
    const auto& g = h.gyros[static_cast<std::size_t>(i)];
    char line[80];
    std::snprintf(line, sizeof line, "  %-4d  %-8s  %s\n", i + 1, fdi::to_string(g.state),
                  g.kind == fdi::FaultKind::kNone ? "-" : fdi::to_string(g.kind));
    out << line;
  }
  out << "  parity residual " << parity_text(h, h.parity_residual) << " σ   chi2 " << parity_text(h, h.chi2)
      << " / " << fixed(h.chi2_threshold, 2) << "   cusum " << parity_text(h, h.cusum) << " / "
      << fixed(h.cusum_threshold, 2) << '\n';
  if (view.attitude) {
    const auto& a = *view.attitude;
    const auto q = to_wxyz(a.q_RB);
    out << "  attitude q = (" << fixed(q[0], 6) << ", " << fixed(q[1], 6) << ", " << fixed(q[2], 6) << ", "
        << fixed(q[3], 6) << ")  σ " << fixed(a.sigma_rad.maxCoeff() * kRadToDeg, 4) << " deg   rate ("
        << fixed(a.omega_BR_B_rad_s.x() * kRadToDeg, 4) << ", "
        << fixed(a.omega_BR_B_rad_s.y() * kRadToDeg, 4) << ", "
        << fixed(a.omega_BR_B_rad_s.z() * kRadToDeg, 4) << ") deg/s   " << fixed(view.attitude_rate_hz, 1)
        << " Hz\n";
  } else {
    out << "  attitude: none received\n";
  }
  out << "  epochs " << h.counters.epochs_accepted << " (rejected " << h.counters.epochs_rejected_time
      << ")   samples " << h.counters.samples_accepted << " | invalid " << h.counters.samples_invalid
      << "  absent " << h.counters.samples_absent << "  late " << c.samples_late << "  duplicate "
      << c.samples_duplicate << "  out-of-order " << c.samples_out_of_order << "  gap " << c.samples_gap
      << "  unknown-gyro " << c.samples_unknown_gyro << "  other-unit " << c.samples_other_unit
      << "  deadlines " << c.deadlines_missed << "  liveliness " << c.liveliness_lost << "  time-outlier "
      << c.time_outlier << "  seq-jump " << c.seq_discontinuity << "  restarts " << c.sensor_restarts << '\n';
  out << "  recent events:" << (view.events.empty() ? " none\n" : "\n");
  for (const auto& e : view.events) {
    // The event on one line, then why: its ledger rows, one per line.
    fdi::FdiEvent shown = e.event;
    shown.ledger.clear();
    out << "    " << fdi::to_json(shown, n) << '\n';
    for (const auto& row : e.event.ledger) out << "        " << fdi::to_text(row) << '\n';
  }
  return out.str();
}

//! Every unit heard, as the readers deliver it.
class MonitorState {
 public:
  MonitorState(const MonitorOptions& options, std::ostream& out) : o_(options), out_(out) {}
  //! Takes Health, events (printed at once with --jsonl) and attitudes received at local time `received`.
  Status take(const ground::GroundReaders& readers, std::int64_t received);
  void update_links(std::int64_t now) {
    for (auto& [unit, view] : units_) update_link(view, now);
  }
  //! --once: every matched Health writer has delivered, with each unit's complete event history.
  bool complete(std::uint32_t health_writers) const;
  //! Each unit's health, as JSON lines or dashboard blocks.
  void print_units(std::int64_t now) const;
  //! The dashboard (or JSON lines) of a refresh; attitude rates measured since the last one.
  void refresh(std::int64_t now);
  Monitored monitored() const { return Monitored{units_.size()}; }

 private:
  bool wanted(const std::string& unit) const { return o_.unit_filter.empty() || unit == o_.unit_filter; }
  Status take_events(const ground::GroundReaders& readers);

  const MonitorOptions& o_;
  std::ostream& out_;
  std::map<std::string, UnitView> units_;
  std::vector<dds::EventView> new_events_;
  std::int64_t last_refresh_ = monotonic_ns();
};

Status MonitorState::take(const ground::GroundReaders& readers, std::int64_t received) {
  auto h = readers.take_health(
      [&](dds::HealthView&& view, std::int64_t) {
        if (!wanted(view.unit)) return;
        UnitView& unit = units_[view.unit];
        unit.health = std::move(view);
        unit.health_received_ns = received;
        unit.writer_alive = true;
      },
      [&](const std::string& unit) {
        if (wanted(unit)) units_[unit].writer_alive = false;
      });
  if (!h) return h;
  if (auto s = take_events(readers); !s) return s;
  auto a =
      readers.take_attitudes([&](const std::string& unit, fdi::AttitudeEstimate&& attitude, std::int64_t) {
        if (!wanted(unit)) return;
        UnitView& view = units_[unit];
        view.attitude = attitude;
        view.attitude_received_ns = received;
        ++view.attitudes_received;
      });
  if (!a) return a;
  if (o_.jsonl) out_.flush();
  return ok_status();
}

Status MonitorState::take_events(const ground::GroundReaders& readers) {
  new_events_.clear();
  auto e = readers.take_events([&](dds::EventView&& view, std::int64_t) {
    if (wanted(view.unit)) new_events_.push_back(std::move(view));
  });
  if (!e) return e;
  std::sort(new_events_.begin(), new_events_.end(), [](const auto& a, const auto& b) {
    return a.unit != b.unit ? a.unit < b.unit : a.event_seq < b.event_seq;
  });
  for (auto& ev : new_events_) {
    UnitView& view = units_[ev.unit];
    view.max_event_seq = std::max(view.max_event_seq, ev.event_seq);
    const int n = view.health ? static_cast<int>(view.health->health.gyros.size()) : 4;
    if (o_.jsonl) out_ << event_json(ev, n) << '\n';
    view.events.push_back(ev);
    if (view.events.size() > kRecentEvents) view.events.pop_front();
  }
  return ok_status();
}

bool MonitorState::complete(std::uint32_t health_writers) const {
  std::size_t complete = 0;
  for (const auto& [unit, view] : units_) {
    if (view.health && view.max_event_seq >= view.health->events_published) ++complete;
  }
  return complete > 0 && complete == units_.size() && (!o_.unit_filter.empty() || complete >= health_writers);
}

void MonitorState::print_units(std::int64_t now) const {
  for (const auto& [unit, view] : units_) {
    if (!view.health) continue;
    if (o_.jsonl) {
      out_ << health_json(unit, view, now) << '\n';
    } else {
      out_ << dashboard_block(unit, view, now);
    }
  }
}

void MonitorState::refresh(std::int64_t now) {
  const double dt = ns_to_seconds(now - last_refresh_);
  for (auto& [unit, view] : units_) {
    view.attitude_rate_hz =
        static_cast<double>(view.attitudes_received - view.attitudes_at_last_refresh) / dt;
    view.attitudes_at_last_refresh = view.attitudes_received;
  }
  last_refresh_ = now;
  if (o_.jsonl) {
    for (const auto& [unit, view] : units_) out_ << health_json(unit, view, now) << '\n';
  } else {
    std::string screen = o_.terminal ? "\033[H\033[2J" : "";
    screen += "tetra monitor — " + std::to_string(units_.size()) + " unit(s)\n";
    for (const auto& [unit, view] : units_) screen += dashboard_block(unit, view, now);
    out_ << screen << (o_.terminal ? "" : "\n");
  }
  out_.flush();
}

//! --once: prints every unit's health once all have arrived; exit 1 when none did within --timeout.
Result<Monitored> monitor_once(const MonitorOptions& o, const ground::GroundReaders& readers,
                               const dds::ShutdownSignal& shutdown, std::ostream& out) {
  MonitorState state(o, out);
  const std::int64_t start = monotonic_ns();
  const std::int64_t give_up_at = start + seconds_to_ns(o.timeout_s);
  const std::int64_t stop_at = o.duration_s > 0 ? start + seconds_to_ns(o.duration_s) : INT64_MAX;
  std::vector<std::intptr_t> triggered;
  while (!shutdown.requested()) {
    if (auto s = state.take(readers, monotonic_ns()); !s) return s.error();
    const std::int64_t now = monotonic_ns();
    state.update_links(now);
    if (shutdown.requested()) break;
    auto matched = readers.health_writers();
    if (!matched) return matched.error();
    if (state.complete(*matched)) {
      state.print_units(now);
      return state.monitored();
    }
    if (now >= give_up_at) {
      std::ostringstream why;
      why << "no health from " << (o.unit_filter.empty() ? "any unit" : "unit " + o.unit_filter) << " within "
          << o.timeout_s << " s";
      return failure(why.str());
    }
    if (now >= stop_at) break;
    if (auto s = readers.wait(std::chrono::nanoseconds(give_up_at - now), triggered); !s) return s.error();
  }
  return state.monitored();
}

//! The dashboard (or JSON lines) every --period until SIGINT/SIGTERM or --duration.
Result<Monitored> monitor_live(const MonitorOptions& o, const ground::GroundReaders& readers,
                               const dds::ShutdownSignal& shutdown, std::ostream& out) {
  MonitorState state(o, out);
  const std::int64_t start = monotonic_ns();
  const std::int64_t period_ns = seconds_to_ns(o.period_s);
  const std::int64_t stop_at = o.duration_s > 0 ? start + seconds_to_ns(o.duration_s) : INT64_MAX;
  std::int64_t next_refresh = start + period_ns;
  std::vector<std::intptr_t> triggered;
  for (;;) {
    if (auto s = state.take(readers, monotonic_ns()); !s) return s.error();
    const std::int64_t now = monotonic_ns();
    state.update_links(now);
    if (shutdown.requested()) break;
    if (now >= next_refresh) {
      state.refresh(now);
      next_refresh = now + period_ns;
    }
    if (now >= stop_at) break;
    if (auto s = readers.wait(std::chrono::nanoseconds(std::min(next_refresh, stop_at) - now), triggered); !s)
      return s.error();
  }
  return state.monitored();
}

}  // namespace

Result<Monitored> monitor_units(const MonitorOptions& o, dds::ShutdownSignal& shutdown, std::ostream& out) {
  auto readers = ground::GroundReaders::open(o.domain, o.unit_filter, shutdown);
  if (!readers) return readers.error();
  return o.once ? monitor_once(o, *readers, shutdown, out) : monitor_live(o, *readers, shutdown, out);
}

}  // namespace tetra::dds_tools
