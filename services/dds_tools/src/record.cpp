// Recording a unit's streams on DDS (tetra/dds_tools/record.hpp).
#include "tetra/dds_tools/record.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sample_merge.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/ground/encode.hpp"
#include "tetra/report/attitude_csv.hpp"
#include "tetra/service/fusion_config.hpp"

namespace tetra::dds_tools {

namespace {

using dds::monotonic_ns;

enum RecordToken : std::intptr_t { kRecordData = 1, kRecordShutdown };
constexpr std::int64_t kIdleGrace_ns = 2'000'000'000;     //!< [ns] wait for the service's last outputs
constexpr std::int64_t kServiceWait_ns = 10'000'000'000;  //!< [ns] wait for the service's Attitude writer
constexpr int kRecorderDepth = 4096;  //!< deeper reader histories than the writers': a burst loses nothing

//! The assembler's settings: the fusion config's (which also names the unit, unless --unit does), or
//! the options'.
Result<service::AssemblerConfig> assembly_settings(RecordOptions& o) {
  service::AssemblerConfig assembly;
  if (!o.config_path.empty()) {
    auto config = service::read_fusion_config(o.config_path);
    if (!config) return config.error();
    if (o.unit.empty()) o.unit = config->unit;
    return config->assembler(config->calibration.gyro_count());
  }
  assembly.gyro_count = o.gyros;
  assembly.nominal_period_ns = seconds_to_ns(1.0 / o.rate_hz);
  assembly.tolerance_ns = o.tolerance_s >= 0 ? seconds_to_ns(o.tolerance_s) : assembly.nominal_period_ns / 4;
  assembly.max_latency_ns = seconds_to_ns(o.max_latency_s);
  assembly.clock_window_ns = seconds_to_ns(service::default_clock_window_s(o.rate_hz));
  return assembly;
}

//! The recorder's end of the wire: every reader, on one waitset.
struct RecordLink {
  dds::Session session;
  std::optional<dds::Reader<tetra_Attitude>> attitude;
  std::optional<dds::Reader<tetra_GyroSample>> gyro;
  std::optional<dds::Reader<tetra_AttitudeReference>> reference;
  std::optional<dds::Reader<tetra_FdiEvent2>> event;
};

//! Recording the service's output too: waits for its Attitude writer before the gyro reader exists,
//! so a simulator waiting for this recorder's gyro reader cannot start before the first attitude can
//! reach us.
Status wait_for_attitude_writer(const dds::Session& session, const dds::Reader<tetra_Attitude>& reader,
                                const dds::ShutdownSignal& shutdown, const std::string& command,
                                std::ostream& err) {
  auto matched = dds::WaitSet::create(session.participant());
  if (!matched) return matched.error();
  if (auto s = reader.enable_statuses(DDS_SUBSCRIPTION_MATCHED_STATUS); !s) return s;
  if (auto s = matched->attach(reader.handle(), 1); !s) return s;
  const std::int64_t give_up = monotonic_ns() + kServiceWait_ns;
  std::vector<std::intptr_t> fired;
  for (;;) {
    auto writers = reader.matched_writers();
    if (!writers) return writers.error();
    if (*writers > 0 || shutdown.requested()) return ok_status();
    const std::int64_t now = monotonic_ns();
    if (now >= give_up) {
      err << command << ": no Attitude writer (fusion service) within 10 s; recording anyway\n";
      return ok_status();
    }
    if (auto s = matched->wait(std::chrono::nanoseconds(give_up - now), fired); !s) return s;
    std::uint32_t status = 0;
    (void)dds_take_status(reader.handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
  }
}

Result<RecordLink> open_record_link(const RecordOptions& o, dds::ShutdownSignal& shutdown,
                                    std::ostream& err) {
  auto session = dds::Session::open(o.domain, o.unit);
  if (!session) return session.error();
  RecordLink link{std::move(session).value(), {}, {}, {}, {}};
  dds::Qos deep;
  deep.reliable().volatile_durability().keep_last(kRecorderDepth);
  using dds::assign;
  if (auto s = assign(link.attitude, link.session.reader<tetra_Attitude>(deep)); !s) return s.error();
  if (!o.attitude_path.empty()) {
    if (auto s = wait_for_attitude_writer(link.session, *link.attitude, shutdown,
                                          report::name_of(o.names, "command"), err);
        !s)
      return s.error();
  }
  // Every gyro sample kept until taken: a writer that keeps its samples until acknowledged (play, ingest)
  // bursting faster than the recorder takes them never has them overwritten in this reader's history.
  dds::Qos every;
  every.reliable().volatile_durability().keep_all();
  if (auto s = assign(link.gyro, link.session.reader<tetra_GyroSample>(every)); !s) return s.error();
  if (auto s = assign(link.reference, link.session.reader<tetra_AttitudeReference>(deep)); !s)
    return s.error();
  if (auto s = assign(link.event, link.session.reader<tetra_FdiEvent2>(dds::event_qos())); !s)
    return s.error();
  for (dds_entity_t reader :
       {link.gyro->handle(), link.reference->handle(), link.attitude->handle(), link.event->handle()}) {
    if (auto s = link.session.watch_data(reader, kRecordData); !s) return s.error();
  }
  if (auto s = link.session.watch_statuses(link.gyro->handle(), DDS_SUBSCRIPTION_MATCHED_STATUS, kRecordData);
      !s)
    return s.error();
  if (auto s = link.session.watch_shutdown(shutdown, kRecordShutdown); !s) return s.error();
  return link;
}

Metadata record_metadata(const std::string& unit, const RunFiles& files) {
  Metadata meta = {{"unit", unit}, {"source", "tetra record"}};
  const auto p = provenance_metadata(provenance(files.input_paths()));
  meta.insert(meta.end(), p.begin(), p.end());
  return meta;
}

//! What is recorded: the log of assembled epochs, and the service's outputs until the end.
class Recording {
 public:
  Recording(RecordOptions& options, service::EpochAssembler& assembler, RunFiles& files, OutputFile& log_out,
            std::ostream& err)
      : o_(options),
        err_(err),
        assembler_(assembler),
        files_(files),
        log_out_(log_out),
        n_(assembler.config().gyro_count),
        values_(static_cast<std::size_t>(n_)) {}

  //! Takes every sample received and writes the epochs they complete by local time `now`.
  Status take(const RecordLink& link, std::int64_t now);
  //! Writes every epoch still open.
  Status flush_epochs();
  //! The service's outputs have arrived up to the last epoch written (or none are recorded).
  bool outputs_done() const {
    return o_.attitude_path.empty() ||
           (last_attitude_ns_ && last_epoch_ns_ && *last_attitude_ns_ >= *last_epoch_ns_);
  }
  //! Flushes, closes the log and writes the optional outputs.
  Status finish(OutputFile* attitude_out, OutputFile* events_out, OutputFile* commands_out);
  std::uint64_t epochs_written() const { return epochs_written_; }
  //! Local time [ns] a sample held for time order is due, or nullopt.
  std::optional<std::int64_t> next_due_ns() const { return merge_.next_due_ns(); }

 private:
  Status take_gyro_samples(const RecordLink& link, std::int64_t now);
  //! The merged samples due by `now` (all with `flush`) into the assembler.
  void give_samples(std::int64_t now, bool flush) {
    merge_.release(now, flush, [&](const tetra_GyroSample& s) {
      (void)assembler_.add_sample(s.gyro, s.seq, s.stamp_ns, s.raw, now, dds::reference_written(s),
                                  dds::promised_samples(s));
    });
  }
  Status take_outputs(const RecordLink& link);
  Status write_epochs();
  Status open_log();

  RecordOptions& o_;
  std::ostream& err_;
  service::EpochAssembler& assembler_;
  RunFiles& files_;
  OutputFile& log_out_;
  int n_;
  GyroLogWriter log_;
  bool reference_stamps_ = false;  //!< the log has ref_stamp_s (CSV): late references are written
  bool log_open_ = false;
  std::string attitude_text_ = report::attitude_header(n_);  // after n_: members initialize in order
  std::map<std::uint64_t, std::string> event_lines_;         // by event_seq: written in order
  std::map<std::uint64_t, std::string> command_lines_;       // acknowledgements, by event_seq
  std::vector<fdi::Epoch> epochs_;
  // A gyro's sample waits for the other gyros' samples of its time for up to 1 s of the recorder's waiting
  // clock: a writer the recorder held back (paused, behind) delivers again only after its retransmission
  // cycle, longer than a sensor's latency limit. A gyro gone silent delays the recording by that second.
  SampleMerge merge_{n_, std::max<std::int64_t>(assembler_.config().max_latency_ns, 1'000'000'000)};
  std::vector<double> values_;
  std::optional<std::int64_t> last_epoch_ns_;
  std::optional<std::int64_t> last_attitude_ns_;
  std::uint64_t epochs_written_ = 0;
};

Status Recording::take(const RecordLink& link, std::int64_t now) {
  if (auto s = take_gyro_samples(link, now); !s) return s;
  if (auto s = take_outputs(link); !s) return s;
  assembler_.poll(now, epochs_);
  return write_epochs();
}

Status Recording::take_gyro_samples(const RecordLink& link, std::int64_t now) {
  auto g = link.gyro->take([&](const tetra_GyroSample& s, const dds_sample_info_t&) {
    const std::string u = dds::from_wire(s.unit);
    if (o_.unit.empty()) {
      o_.unit = u;
      err_ << report::name_of(o_.names, "command") << ": recording unit " << o_.unit << '\n';
    }
    if (u == o_.unit) merge_.add(s, now);  // one gyro's samples after another's: merged in time order
  });
  if (!g) return g.error();
  give_samples(now, false);
  auto r = link.reference->take([&](const tetra_AttitudeReference& s, const dds_sample_info_t&) {
    if (dds::from_wire(s.unit) == o_.unit)
      assembler_.add_reference(s.stamp_ns, from_wxyz(s.q_RB[0], s.q_RB[1], s.q_RB[2], s.q_RB[3]));
  });
  if (!r) return r.error();
  return ok_status();
}

Status Recording::take_outputs(const RecordLink& link) {
  auto a = link.attitude->take([&](const tetra_Attitude& s, const dds_sample_info_t&) {
    if (dds::from_wire(s.unit) != o_.unit) return;
    const auto attitude = dds::from_wire(s);
    report::append_attitude_row(attitude_text_, ns_to_seconds(attitude.stamp_ns), attitude, n_);
    last_attitude_ns_ = attitude.stamp_ns;
  });
  if (!a) return a.error();
  auto e = link.event->take([&](const tetra_FdiEvent2& s, const dds_sample_info_t&) {
    const auto view = dds::from_wire(s);
    if (view.unit != o_.unit) return;
    event_lines_[view.event_seq] = fdi::to_json(view.event, n_);
    if (view.command_id != 0) command_lines_[view.event_seq] = ground::json_text(ground::ack_json(view, n_));
  });
  if (!e) return e.error();
  return ok_status();
}

Status Recording::open_log() {
  if (log_open_) return ok_status();
  // A reference delivered after its epoch goes on the row it reached with its own time (CSV: ref_stamp_s), so
  // replay fuses it at that time as the service did; HDF5 logs have no such column and leave it out.
  reference_stamps_ = !is_hdf5_path(log_out_.path());
  log_.set_reference_stamps(reference_stamps_);
  if (auto s = log_.open(log_out_, n_, true, false, record_metadata(o_.unit, files_)); !s) return s;
  log_open_ = true;
  return ok_status();
}

Status Recording::write_epochs() {
  for (const auto& epoch : epochs_) {
    if (auto s = open_log(); !s) return s;
    for (int i = 0; i < n_; ++i)
      values_[static_cast<std::size_t>(i)] = epoch.raw[static_cast<std::size_t>(i)];
    std::optional<std::array<double, 4>> ref;
    std::optional<double> ref_stamp;
    // A reference delivered after its epoch (fused by the service at its own stamp): on the row it reached,
    // with its own time (ref_stamp_s); without that column (HDF5) it is left out rather than written as if
    // taken at this row's time (docs/dds.md, "Known limits").
    if (epoch.reference_q_RB && epoch.reference_stamp_ns)
      ref_stamp = ns_to_seconds(*epoch.reference_stamp_ns);
    if (epoch.reference_q_RB && (!ref_stamp || reference_stamps_)) ref = to_wxyz(*epoch.reference_q_RB);
    if (auto s = log_.write(ns_to_seconds(epoch.stamp_ns), values_, epoch.present, ref, ref_stamp); !s)
      return s;
    last_epoch_ns_ = epoch.stamp_ns;
    ++epochs_written_;
  }
  epochs_.clear();
  return ok_status();
}

Status Recording::flush_epochs() {
  give_samples(monotonic_ns(), true);
  assembler_.poll(INT64_MAX, epochs_);
  return write_epochs();
}

Status Recording::finish(OutputFile* attitude_out, OutputFile* events_out, OutputFile* commands_out) {
  if (auto s = flush_epochs(); !s) return s;
  if (auto s = open_log(); !s) return s;
  if (auto s = log_.close(); !s) return s;
  if (attitude_out) {
    std::string text;
    for (const auto& [key, value] : record_metadata(o_.unit, files_)) append_metadata(text, key, value);
    if (auto s = attitude_out->write(text + attitude_text_); !s) return s;
  }
  const auto write_lines = [](OutputFile* out, const std::map<std::uint64_t, std::string>& lines) {
    std::string text;
    for (const auto& [seq, line] : lines) text += line + '\n';
    return out ? out->write(text) : ok_status();
  };
  if (auto s = write_lines(events_out, event_lines_); !s) return s;
  return write_lines(commands_out, command_lines_);
}

// The recorder's clock for the epoch assembler (its latency limit, its receive clock): the time it spent
// waiting for data. A stall of the recorder itself (SIGSTOP, a loaded machine) never makes the writers'
// samples late: a wait that ended more than kStallSlack_ns past its timeout counts nothing, and the
// recorder's own work counts nothing, so an epoch whose last sample is still on its way (retransmitted
// once the recorder runs again) is not given up while the recorder was not listening.
class WaitingClock {
 public:
  std::int64_t now() const { return now_; }
  //! Waits up to `timeout` [ns] for data.
  Status wait(const RecordLink& link, std::int64_t timeout, std::vector<std::intptr_t>& triggered) {
    const std::int64_t before = monotonic_ns();
    if (auto s = link.session.wait(std::chrono::nanoseconds(timeout), triggered); !s) return s;
    const std::int64_t waited = monotonic_ns() - before;
    if (waited <= timeout + kStallSlack_ns) now_ += waited;
    return ok_status();
  }

 private:
  static constexpr std::int64_t kStallSlack_ns = 10'000'000;
  std::int64_t now_ = monotonic_ns();
};

//! Records until a signal, --duration, or (--until-idle) the gyro writers gone and the service's last
//! outputs in.
Status record_until_done(const RecordOptions& o, const RecordLink& link, Recording& recording,
                         const service::EpochAssembler& assembler, const dds::ShutdownSignal& shutdown) {
  bool writers_seen = false;
  std::int64_t idle_since = -1;  // [ns] local time the gyro writers went away; -1: not idle
  const std::int64_t stop_at = o.duration_s > 0 ? monotonic_ns() + seconds_to_ns(o.duration_s) : INT64_MAX;
  std::vector<std::intptr_t> triggered;
  WaitingClock clock;
  for (;;) {
    const std::int64_t now = monotonic_ns();
    if (auto s = recording.take(link, clock.now()); !s) return s;
    std::uint32_t status = 0;
    (void)dds_take_status(link.gyro->handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
    auto matched = link.gyro->matched_writers();
    if (!matched) return matched.error();
    if (*matched > 0) {
      writers_seen = true;
      idle_since = -1;
    } else if (writers_seen && idle_since < 0) {
      idle_since = now;
    }
    if (shutdown.requested() || now >= stop_at) return ok_status();
    const bool idle = o.until_idle && idle_since >= 0;
    if (idle) {
      // The writers are gone: take what they sent since the take above (it is all in: they waited for
      // its acknowledgement), flush the open epochs, then wait (briefly) for the service's outputs.
      if (auto s = recording.take(link, clock.now()); !s) return s;
      if (auto s = recording.flush_epochs(); !s) return s;
      if (recording.outputs_done() || now - idle_since >= kIdleGrace_ns) return ok_status();
    }
    std::int64_t timeout = std::min(stop_at - now, std::int64_t{1'000'000'000});
    if (auto due = assembler.next_due_ns()) timeout = std::min(timeout, *due - clock.now());
    if (auto due = recording.next_due_ns()) timeout = std::min(timeout, *due - clock.now());
    if (idle) timeout = std::min(timeout, idle_since + kIdleGrace_ns - now);
    if (auto s = clock.wait(link, std::max<std::int64_t>(timeout, 0), triggered); !s) return s;
  }
}

}  // namespace

Result<Recorded> record_unit(const RecordOptions& options, dds::ShutdownSignal& shutdown, std::ostream& err) {
  RecordOptions o = options;  // the unit is the first one seen when none is given
  RunFiles files;
  if (!o.config_path.empty()) files.add_input(o.config_path, report::name_of(o.names, "config_path"));
  OutputFile* log_out = nullptr;
  OutputFile* attitude_out = nullptr;
  OutputFile* events_out = nullptr;
  OutputFile* commands_out = nullptr;
  const std::string out_name = report::name_of(o.names, "out_path");
  const std::string attitude_name = report::name_of(o.names, "attitude_path");
  const std::string events_name = report::name_of(o.names, "events_path");
  const std::string commands_name = report::name_of(o.names, "commands_path");
  if (Status s = files.add_outputs({{o.out_path, out_name.c_str(), &log_out},
                                    {o.attitude_path, attitude_name.c_str(), &attitude_out},
                                    {o.events_path, events_name.c_str(), &events_out},
                                    {o.commands_path, commands_name.c_str(), &commands_out}});
      !s)
    return s.error();
  if (log_out == nullptr) return bad_input(ErrorSubject("out_path"), "is required");
  auto assembly = assembly_settings(o);
  if (!assembly) return assembly.error();
  auto assembler = service::EpochAssembler::create(*assembly);
  if (!assembler) return assembler.error();
  auto link = open_record_link(o, shutdown, err);
  if (!link) return link.error();

  Recording recording(o, *assembler, files, *log_out, err);
  if (auto s = record_until_done(o, *link, recording, *assembler, shutdown); !s) return s.error();
  if (auto s = recording.finish(attitude_out, events_out, commands_out); !s) return s.error();
  if (auto s = files.commit(); !s) return s.error();
  Recorded recorded{o.unit, recording.epochs_written(), assembler->counters(), 0, 0};
  auto gyro_lost = link->gyro->samples_lost();
  if (!gyro_lost) return gyro_lost.error();
  // Lost on the wire (a writer's history overflowed), or promised for an epoch and never in.
  recorded.gyro_samples_lost = *gyro_lost + assembler->counters().samples_promised_lost;
  if (!o.attitude_path.empty()) {
    auto attitude_lost = link->attitude->samples_lost();
    if (!attitude_lost) return attitude_lost.error();
    recorded.attitudes_lost = *attitude_lost;
  }
  return recorded;
}

}  // namespace tetra::dds_tools
