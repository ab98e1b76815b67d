#include "tetra/service/fusion_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>

#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/service/realtime.hpp"

namespace tetra::service {

namespace {

enum Token : std::intptr_t {
  kGyroData = 1,
  kGyroStatus,
  kReferenceData,
  kCommandData,
  kPeerHealth,
  kWake,
  kStop
};
constexpr std::uint32_t kGyroStatuses = DDS_REQUESTED_DEADLINE_MISSED_STATUS |
                                        DDS_REQUESTED_INCOMPATIBLE_QOS_STATUS |
                                        DDS_SUBSCRIPTION_MATCHED_STATUS;

using dds::assign;
using dds::monotonic_ns;

}  // namespace

Status FusionService::open(dds_domainid_t domain, dds::ShutdownSignal* shutdown) {
  deadline_ns_ = config_.deadline_ns();
  shutdown_ = shutdown;
  if (auto s = assign(session_, dds::Session::open(domain, config_.unit)); !s) return s;
  if (Status s = open_duplicate_watch(domain); !s) return s;
  if (auto s = open_endpoints(); !s) return s;
  if (duplicates_) {
    if (auto s = duplicates_->set_own_writer(health_writer_->handle()); !s) return s;
  }
  return open_waitset();
}

Status FusionService::open_duplicate_watch(dds_domainid_t domain) {
  auto watch = DuplicateWatch::create(*session_, config_.unit, static_cast<int>(domain));
  if (!watch && config_.security) {
    // A DDS Security identity granted no Health subscription (permissions made before the watch).
    spdlog::warn(
        "fusion: this identity may not subscribe to Health ({}): another service of unit {} would go "
        "undetected; grant the fusion role Health (scripts/security/make_pki.sh)",
        watch.error().message, config_.unit);
    return ok_status();
  }
  if (auto s = assign(duplicates_, std::move(watch)); !s) return s;
  return duplicates_->probe(session_->participant(), DuplicateWatch::kProbe, [this] { return stopping(); });
}

Status FusionService::open_endpoints() {
  const dds::Session& session = *session_;
  const auto sample_period = std::chrono::nanoseconds(deadline_ns_ / 3);
  if (auto s =
          assign(gyro_reader_, session.reader<tetra_GyroSample>(dds::gyro_sample_reader_qos(sample_period)));
      !s)
    return s;
  if (auto s = assign(reference_reader_, session.reader<tetra_AttitudeReference>(dds::reference_qos())); !s)
    return s;
  if (auto s = assign(command_reader_, session.reader<tetra_Command>(dds::command_qos())); !s) return s;
  if (auto s = assign(attitude_writer_, session.writer<tetra_Attitude>(dds::attitude_writer_qos())); !s)
    return s;
  if (auto s = assign(health_writer_, session.writer<tetra_Health>(dds::health_qos())); !s) return s;
  if (auto s = assign(event_writer_, session.writer<tetra_FdiEvent2>(dds::event_qos())); !s) return s;
  if (!config_.ros2.enabled) return ok_status();
  const Ros2ViewConfig names = config_.ros2.resolved(config_.unit);
  dds::Ros2View::Settings ros2{{names.name, names.frame_id, names.reference_frame_id},
                               config_.unit,
                               config_.calibration,
                               config_.sample_rate_hz,
                               config_.pipeline.default_arw_dps_rtHz};
  return assign(ros2_view_, dds::Ros2View::create(session.participant(), std::move(ros2)));
}

Status FusionService::open_waitset() {
  dds::Session& session = *session_;
  if (!listener_dispatch()) {
    if (auto s = session.watch_data(gyro_reader_->handle(), kGyroData); !s) return s;
  }
  if (auto s = session.watch_data(reference_reader_->handle(), kReferenceData); !s) return s;
  if (auto s = session.watch_data(command_reader_->handle(), kCommandData); !s) return s;
  if (duplicates_) {
    if (auto s = session.watch_data(duplicates_->reader_handle(), kPeerHealth); !s) return s;
  }
  if (auto s = session.watch_statuses(gyro_reader_->handle(), kGyroStatuses, kGyroStatus); !s) return s;
  auto wake = session.add_guard(kWake);
  if (!wake) return wake.error();
  wake_ = *wake;
  auto stop = session.add_guard(kStop);
  if (!stop) return stop.error();
  if (shutdown_ != nullptr) shutdown_->set_guard((*stop)->handle());
  stop_.store(*stop);
  return ok_status();
}

void FusionService::request_stop() {
  stop_requested_.store(true);
  if (const dds::Condition* stop = stop_.load()) (void)stop->trigger();
}

void FusionService::on_gyro_data(dds_entity_t, void* self) {
  auto& service = *static_cast<FusionService*>(self);
  const std::lock_guard lock(service.mutex_);
  if (service.listener_error_) return;
  if (service.config_.realtime_priority && !service.listener_realtime_) {
    service.listener_realtime_ = true;  // Cyclone's receive thread: the first callback is on it
    make_step_thread_realtime(*service.config_.realtime_priority, "receive thread (gyro listener)");
  }
  auto status = service.ingest(monotonic_ns());
  if (!status) service.listener_error_ = status.error();
  // An epoch still waiting for samples is due before the waitset thread would wake by itself.
  const auto due = service.assembler_.next_due_ns();
  if (!status || (due && *due < service.scheduled_wake_ns_)) (void)service.wake_->trigger();
}

void FusionService::stop_listener() {
  if (listening_ && gyro_reader_) (void)gyro_reader_->on_data_available(nullptr, nullptr);
  listening_ = false;
}

// --realtime: a failure is a warning naming what failed; the service goes on without it.
void FusionService::make_step_thread_realtime(int priority, const char* thread) {
  if (Status s = make_thread_realtime(priority); !s) {
    spdlog::warn("fusion: --realtime: {}: {}", thread, s.error().message);
    return;
  }
  spdlog::info("fusion: --realtime: {} under SCHED_FIFO at priority {}", thread, priority);
}

void FusionService::apply_realtime() {
  if (!config_.realtime_priority) return;
  if (Status s = lock_memory(); !s) {
    spdlog::warn("fusion: --realtime: {}", s.error().message);
  } else {
    spdlog::info("fusion: --realtime: memory locked (mlockall: current and future pages)");
  }
  make_step_thread_realtime(*config_.realtime_priority, "waitset thread");
}

Status FusionService::run() {
  apply_realtime();
  {
    const std::lock_guard lock(mutex_);
    started_ns_ = monotonic_ns();
    next_health_ns_ = started_ns_;
    if (auto s = publish_health(started_ns_, true); !s) return s;
  }
  if (listener_dispatch()) {
    if (auto s = gyro_reader_->on_data_available(&FusionService::on_gyro_data, this); !s) return s;
    listening_ = true;
  }
  spdlog::info("fusion: unit {} running, {} gyros, {} Hz, gyro samples dispatched by the {}", config_.unit,
               n_gyros_, config_.sample_rate_hz, listener_dispatch() ? "listener" : "waitset");
  Status status = loop();
  stop_listener();  // before anything the listener uses goes away
  if (!status) return status;
  if (shutdown_ != nullptr && shutdown_->requested()) {
    spdlog::info("fusion: signal {} received, shutting down", shutdown_->signal_number());
  } else {
    spdlog::info("fusion: stop requested, shutting down");
  }
  const std::lock_guard lock(mutex_);
  return publish_health(monotonic_ns(), true);
}

Status FusionService::loop() {
  std::vector<std::intptr_t> triggered;
  std::int64_t wake = 0;
  {
    const std::lock_guard lock(mutex_);
    wake = scheduled_wake_ns_ = next_wake_ns(monotonic_ns());
  }
  while (!stopping()) {
    if (auto s = session_->wait(std::chrono::nanoseconds(wake - monotonic_ns()), triggered); !s) return s;
    if (stopping()) break;
    const std::lock_guard lock(mutex_);
    if (auto s = wake_->clear(); !s) return s;
    if (listener_error_) return *listener_error_;
    const std::int64_t now = monotonic_ns();
    if (auto s = handle_wakeup(triggered, now); !s) return s;
    // A listener that opens an epoch after this sees the new time, and wakes this thread if the
    // epoch is due earlier; one that opened it before is in this computation.
    wake = scheduled_wake_ns_ = next_wake_ns(now);
  }
  return ok_status();
}

std::int64_t FusionService::next_wake_ns(std::int64_t now_ns) const {
  std::int64_t wake = next_health_ns_;
  if (auto due = assembler_.next_due_ns()) wake = std::min(wake, *due);
  std::int64_t last_any_arrival = 0;
  for (int g = 1; g <= n_gyros_; ++g) {
    const std::int64_t arrival = last_arrival_ns_[static_cast<std::size_t>(g - 1)];
    last_any_arrival = std::max(last_any_arrival, arrival);
    // Gyros not yet absent are checked for silence at their deadline.
    if (!assembler_.absent(g))
      wake = std::min(wake, std::max({arrival, started_ns_, resumed_ns_}) + deadline_ns_ + 1);
  }
  // While samples flow, an epoch the next sample opens is due no earlier than this: waking here
  // spares the listener from waking this thread for every epoch.
  const std::int64_t next_epoch_due = last_any_arrival + assembler_.config().max_latency_ns;
  if (listener_dispatch() && next_epoch_due > now_ns) wake = std::min(wake, next_epoch_due);
  return wake;
}

Status FusionService::handle_wakeup(const std::vector<std::intptr_t>& triggered, std::int64_t now) {
  bool deadline_status = false;
  bool matched_changed = false;
  const auto fired = [&](Token token) {
    return std::find(triggered.begin(), triggered.end(), token) != triggered.end();
  };
  if (fired(kPeerHealth)) {
    if (auto s = duplicates_ ? duplicates_->check() : ok_status(); !s) return s;
  }
  const bool command_data = fired(kCommandData);
  const bool gyro_data = fired(kGyroData);
  if (fired(kGyroStatus)) {
    if (auto s = take_gyro_statuses(deadline_status, matched_changed); !s) return s;
  }
  if (gyro_data) {
    if (auto s = ingest(now); !s) return s;
  }
  if (auto s = take_references(); !s) return s;
  if (command_data) {
    if (auto s = take_commands(); !s) return s;
  }
  const bool newly_absent = check_deadlines(now, deadline_status);
  if (auto s = report_silence(now); !s) return s;
  if (auto s = process_epochs(now); !s) return s;
  if (command_data || newly_absent || matched_changed || now >= next_health_ns_) {
    if (auto s = publish_health(now, matched_changed); !s) return s;
  }
  return ok_status();
}

Status FusionService::take_gyro_statuses(bool& deadline_missed, bool& matched_changed) {
  std::uint32_t status = 0;
  (void)dds_take_status(gyro_reader_->handle(), &status, kGyroStatuses);
  deadline_missed = (status & DDS_REQUESTED_DEADLINE_MISSED_STATUS) != 0;
  if ((status & DDS_SUBSCRIPTION_MATCHED_STATUS) != 0) {
    // A sensor (or simulator) came or went: say so in Health at once (a simulator waits for it).
    auto matched = gyro_reader_->matched_writers();
    if (!matched) return matched.error();
    gyro_writers_ = *matched;
    spdlog::info("fusion: {} GyroSample writer(s) matched", gyro_writers_);
    matched_changed = true;
  }
  if ((status & DDS_REQUESTED_INCOMPATIBLE_QOS_STATUS) != 0) {
    dds_requested_incompatible_qos_status_t qos_status{};
    (void)dds_get_requested_incompatible_qos_status(gyro_reader_->handle(), &qos_status);
    const std::uint32_t policy = qos_status.last_policy_id;
    if (policy == DDS_DEADLINE_QOS_POLICY_ID) {
      spdlog::warn(
          "fusion: a GyroSample writer offers incompatible QoS: deadline (policy id {}; its deadline must "
          "be at most {} s: sample_rate_hz and speed must match the sensor's)",
          policy, ns_to_seconds(deadline_ns_));
    } else {
      spdlog::warn("fusion: a GyroSample writer offers incompatible QoS: {} (policy id {}; docs/dds.md)",
                   dds::qos_policy_name(policy), policy);
    }
  }
  return ok_status();
}

Status FusionService::ingest(std::int64_t now_ns) {
  // Gyro samples before references: a reference written before an epoch's samples is then
  // already in its reader when the epoch completes (docs/dds.md).
  if (auto s = take_gyro_samples(now_ns); !s) return s;
  if (auto s = take_references(); !s) return s;
  if (auto s = report_silence(now_ns); !s) return s;
  return process_epochs(now_ns);
}

Status FusionService::take_gyro_samples(std::int64_t now_ns) {
  const bool was_silent = assembler_.all_absent();
  auto taken = gyro_reader_->take(
      [&](const tetra_GyroSample& sample, const dds_sample_info_t&) {
        if (dds::from_wire(sample.unit) != config_.unit) {
          ++assembler_.counters().samples_other_unit;
          other_unit_heard_ = dds::from_wire(sample.unit);
          return;
        }
        ++own_samples_;
        const int gyro = sample.gyro;
        const auto verdict =
            assembler_.add_sample(gyro, sample.seq, sample.stamp_ns, sample.raw, now_ns,
                                  dds::reference_written(sample), dds::promised_samples(sample));
        if (gyro >= 1 && gyro <= n_gyros_) last_arrival_ns_[static_cast<std::size_t>(gyro - 1)] = now_ns;
        if (verdict != Verdict::kAccepted) {
          spdlog::debug("fusion: gyro {} seq {} stamp {} ns: {}", gyro, sample.seq, sample.stamp_ns,
                        to_string(verdict));
        }
      },
      [&](const dds_sample_info_t& info) {
        // No writer left for an instance (liveliness lost, writer gone): that gyro is absent.
        if (info.instance_state == DDS_IST_ALIVE) return;
        tetra_GyroSample key{};
        if (gyro_reader_->instance_key(info.instance_handle, key) &&
            dds::from_wire(key.unit) == config_.unit) {
          if (!assembler_.absent(key.gyro))
            spdlog::warn("fusion: gyro {} has no live writer: absent", key.gyro);
          assembler_.mark_absent(key.gyro, AbsentReason::kLiveliness);
        }
        dds_sample_free(&key, &tetra_GyroSample_desc, DDS_FREE_CONTENTS);
      });
  if (!taken) return taken.error();
  warn_other_unit(now_ns);
  if (was_silent && !assembler_.all_absent()) resumed_ns_ = now_ns;  // deadlines re-armed from now
  if (assembler_.counters().sensor_restarts != last_restarts_) {
    last_restarts_ = assembler_.counters().sensor_restarts;
    spdlog::warn(
        "fusion: sensor time restarted (after silence, or every gyro moved to a new time base): "
        "pipeline reset");
    pipeline_.reset();
  }
  return ok_status();
}

void FusionService::warn_other_unit(std::int64_t now_ns) {
  // Rate-limited (once per kOtherUnitWarnPeriod_ns): samples for another unit and none for ours.
  const std::uint64_t other = assembler_.counters().samples_other_unit;
  if (other == other_at_warning_ || now_ns < next_other_warning_ns_) return;
  if (own_samples_ == own_at_warning_) {
    spdlog::warn(
        "fusion: hearing GyroSample for unit '{}' ({} samples of other units so far) and none for "
        "this service's unit '{}': check the unit names",
        other_unit_heard_, other, config_.unit);
  }
  other_at_warning_ = other;
  own_at_warning_ = own_samples_;
  next_other_warning_ns_ = now_ns + kOtherUnitWarnPeriod_ns;
}

Status FusionService::take_references() {
  std::optional<CrowdedOutReference> crowded;
  auto taken = reference_reader_->take([&](const tetra_AttitudeReference& ref, const dds_sample_info_t&) {
    if (dds::from_wire(ref.unit) != config_.unit) return;
    auto gave_way =
        assembler_.add_reference(ref.stamp_ns, from_wxyz(ref.q_RB[0], ref.q_RB[1], ref.q_RB[2], ref.q_RB[3]));
    if (gave_way && !crowded) crowded = gave_way;
  });
  if (!taken) return taken.error();
  return crowded ? report_crowded_out(*crowded) : ok_status();
}

Status FusionService::report_crowded_out(const CrowdedOutReference& crowded) {
  // The first of a run of late references that gave way before reaching the pipeline: counted in Health's
  // references_too_late like one beyond the horizon, and said by the same typed event.
  fdi::FdiEvent event;
  event.stamp_ns = pipeline_.health().stamp_ns;  // the last epoch fused
  event.type = fdi::EventType::kReferenceLate;
  event.statistic = crowded.late_s;
  char text[200];
  std::snprintf(text, sizeof text,
                "attitude reference %.3f s late crowded out: more than %zu references waited for the next "
                "epoch; the oldest gives way, as does each one until all have gone on",
                crowded.late_s, EpochAssembler::kMaxLateReferences);
  event.detail = text;
  return publish_event(event, 0, {});
}

Status FusionService::take_commands() {
  std::vector<tetra_Command> commands;
  auto taken = command_reader_->take([&](const tetra_Command& command, const dds_sample_info_t&) {
    if (dds::from_wire(command.unit) == config_.unit) commands.push_back(command);
  });
  if (!taken) return taken.error();
  for (const auto& command : commands) {
    // Stamped with the sensor time of the last epoch fused; before the first, 1 ns before time zero
    // (so that `replay --commands` applies it before an epoch stamped 0, as here).
    const std::int64_t stamp = fused_any_ ? pipeline_.health().stamp_ns : -1;
    fdi::FdiEvent ack;
    switch (command.kind) {
      case tetra_COMMAND_RESET:
        ack = pipeline_.reset_command(stamp);
        break;
      case tetra_COMMAND_EXCLUDE:
        ack = pipeline_.exclude(command.gyro, stamp, command.force);
        break;
      case tetra_COMMAND_REINSTATE:
        ack = pipeline_.reinstate(command.gyro, stamp);
        break;
    }
    const dds::CommandAudit audit{command.kind, command.force, dds::from_wire(command.operator_id),
                                  dds::from_wire(command.origin)};
    spdlog::info("fusion: command {} from operator '{}' at '{}' {}: {}", command.command_id,
                 audit.operator_id, audit.origin, ack.refused() ? "refused" : "accepted",
                 fdi::to_json(ack, n_gyros_));
    if (auto s = publish_event(ack, command.command_id, audit); !s) return s;
  }
  return ok_status();
}

Status FusionService::report_silence(std::int64_t now_ns) {
  // Every gyro silent: counted in Health at once; a `lost` event once the silence has lasted
  // kMinOutageReported_s, and then a `cleared` when samples come back (hysteresis: a loaded machine's
  // brief gaps do not flood the event log). Before the first epoch the service is waiting, not lost.
  const bool silent = fused_any_ && assembler_.all_absent();
  if (silent && !all_silent_) {
    all_silent_ = true;
    silent_since_ns_ = now_ns;
    ++unit_silences_;
  }
  if (!silent) all_silent_ = false;
  const bool report_lost =
      all_silent_ && !lost_reported_ && now_ns - silent_since_ns_ >= seconds_to_ns(kMinOutageReported_s);
  const bool report_cleared = !all_silent_ && lost_reported_;
  if (!report_lost && !report_cleared) return ok_status();
  lost_reported_ = report_lost;
  fdi::FdiEvent event;
  event.stamp_ns = pipeline_.health().stamp_ns;  // the last epoch fused: a time the unit had
  event.type = report_lost ? fdi::EventType::kLost : fdi::EventType::kCleared;
  event.detail = report_lost ? "all gyros silent" : "gyro samples back";
  for (int g = 1; g <= n_gyros_; ++g) {
    if (!assembler_.absent(g)) event.gyros |= GyroMask{1} << static_cast<unsigned>(g - 1);
  }
  return publish_event(event, 0, {});
}

bool FusionService::check_deadlines(std::int64_t now_ns, bool dds_reported) {
  bool any = false;
  for (int g = 1; g <= n_gyros_; ++g) {
    if (assembler_.absent(g)) continue;
    const std::int64_t since =
        std::max({last_arrival_ns_[static_cast<std::size_t>(g - 1)], started_ns_, resumed_ns_});
    if (now_ns - since >= deadline_ns_) {
      spdlog::warn("fusion: gyro {} silent for 3 sample periods{}: absent", g,
                   dds_reported ? " (DDS deadline)" : "");
      assembler_.mark_absent(g, AbsentReason::kDeadline);
      any = true;
    }
  }
  return any;
}

Status FusionService::process_epochs(std::int64_t now_ns) {
  epochs_.clear();
  assembler_.poll(now_ns, epochs_);
  for (const auto& epoch : epochs_) {
    const fdi::StepResult& result = pipeline_.step(epoch);
    fused_any_ = true;
    // Events before the attitude of the same epoch: a reader that has the attitude has its events.
    for (const auto& event : result.events) {
      if (auto s = publish_event(event, 0, {}); !s) return s;
    }
    if (result.accepted) {
      tetra_Attitude wire{};
      if (auto s = dds::to_wire(config_.unit, result.attitude, wire); !s) return s;
      if (auto s = attitude_writer_->write(wire); !s) return s;
      if (ros2_view_) {
        if (auto s = ros2_view_->publish(result.attitude); !s) return s;
      }
    }
    if (auto s = publish_health(now_ns, false); !s) return s;
  }
  return ok_status();
}

Status FusionService::publish_event(const fdi::FdiEvent& event, std::uint64_t command_id,
                                    const dds::CommandAudit& audit) {
  dds::EventView view{config_.unit, ++event_seq_, command_id, event, audit};
  if (auto s = dds::to_wire(view, event_wire_); !s) return s;
  if (event.type != fdi::EventType::kCommand) spdlog::info("fusion: event {}", fdi::to_json(event, n_gyros_));
  return event_writer_->write(event_wire_.msg);
}

void FusionService::current_health(fdi::Health& health) const {
  // The pipeline's health, with what only the service knows: gyros whose streams stopped (deadline,
  // liveliness) are absent and out of the solution; when the rest cannot determine the attitude, LOST.
  health = pipeline_.health();
  health.gyros.resize(static_cast<std::size_t>(n_gyros_));
  for (int g = 1; g <= n_gyros_; ++g) {
    if (!assembler_.absent(g)) continue;
    auto& gyro = health.gyros[static_cast<std::size_t>(g - 1)];
    if (gyro.state == fdi::GyroState::kOk) gyro.state = fdi::GyroState::kAbsent;
    health.used = without_gyro(health.used, g);
  }
  if (!pipeline_.observable(health.used)) health.mode = fdi::Mode::kLost;
}

Status FusionService::publish_health(std::int64_t now_ns, bool force) {
  fdi::Health& health = health_scratch_;
  current_health(health);
  bool changed = !last_health_ || last_health_->mode != health.mode || last_health_->used != health.used ||
                 last_health_->gyros.size() != health.gyros.size();
  for (std::size_t i = 0; !changed && i < health.gyros.size(); ++i) {
    changed = last_health_->gyros[i].state != health.gyros[i].state ||
              last_health_->gyros[i].kind != health.gyros[i].kind;
  }
  if (!force && !changed && now_ns < next_health_ns_) return ok_status();
  if (changed && last_health_) {
    spdlog::info("fusion: health {} gyros {}", fdi::to_string(health.mode),
                 mask_to_string(health.used, n_gyros_));
  }
  dds::WireHealth wire;
  service::AssemblerCounters counters = assembler_.counters();
  counters.unit_silences = unit_silences_;
  if (auto s = dds::to_wire(config_.unit, health, counters, wire); !s) return s;
  wire.msg.events_published = event_seq_;
  wire.msg.gyro_writers = gyro_writers_;
  wire.msg.health_period_s = config_.health_period_s;
  wire.msg.reference_horizon_s = pipeline_.config().reference_horizon_s;
  if (auto s = health_writer_->write(wire.msg); !s) return s;
  if (ros2_view_) {
    if (auto s = ros2_view_->publish(health); !s) return s;
  }
  if (last_health_) {
    *last_health_ = health;  // reuses the storage
  } else {
    last_health_ = health;
  }
  next_health_ns_ = now_ns + seconds_to_ns(config_.health_period_s);
  return ok_status();
}

}  // namespace tetra::service
