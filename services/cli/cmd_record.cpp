// tetra record -o LOG.csv — the gyro and reference streams of one unit on DDS, written as a
// replayable gyro log (docs/interfaces.md §2.2). Epochs are assembled exactly as `tetra fusion` does (same
// assembler, same settings when given the service's --config), so `tetra replay` of the log sees
// the epochs the service saw. Optionally also the service's Attitude (docs/interfaces.md §2.4) and FdiEvents
// (§2.5). Stops on SIGINT/SIGTERM, after --duration, or with --until-idle when the gyro writers are gone.

#include <algorithm>
#include <iostream>
#include <map>
#include <string>

#include "attitude_csv.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/ground/encode.hpp"
#include "tetra/service/fusion_config.hpp"

namespace tetra::cli {

namespace {

using namespace std::chrono_literals;
enum Token : std::intptr_t { kData = 1, kShutdown };
constexpr std::int64_t kIdleGrace_ns = 2'000'000'000;  //!< [ns] wait for the service's last outputs

}  // namespace

namespace {

Metadata record_metadata(const std::string& unit, const RunFiles& files) {
  Metadata meta = {{"unit", unit}, {"source", "tetra record"}};
  const auto p = provenance_metadata(provenance(files.input_paths()));
  meta.insert(meta.end(), p.begin(), p.end());
  return meta;
}

}  // namespace

int cmd_record(int argc, char** argv) {
  dds::ShutdownSignal shutdown;
  CLI::App app{"Record a unit's gyro and reference streams on DDS as a replayable gyro log.", "record"};
  std::string unit;
  std::string out_path;
  std::string config_path;
  std::string attitude_path;
  std::string events_path;
  std::string commands_path;
  int gyros = 4;
  double rate_hz = 100.0;
  double tolerance_s = -1.0;  // [s] default: a quarter period
  double max_latency_s = 0.02;
  double duration_s = 0.0;
  bool until_idle = false;
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  app.add_option("-o,--out", out_path, "gyro log to write (CSV, or HDF5 when named .h5)")->required();
  app.add_option("--unit", unit, "the unit to record (default: the first one seen)");
  app.add_option("--config", config_path, "take unit, gyro count and assembly settings from a fusion config");
  app.add_option("--gyros", gyros, "number of gyros N (columns g1..gN)")
      ->check(CLI::Range(1, dds::kMaxGyrosOnWire));
  app.add_option("--rate", rate_hz, "[Hz] nominal sample rate")->check(CLI::PositiveNumber);
  app.add_option("--tolerance", tolerance_s,
                 "[s] stamps this close form one epoch (default: a quarter period)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-latency", max_latency_s, "[s] longest wait for an epoch's missing samples")
      ->check(CLI::PositiveNumber);
  app.add_option("--attitude", attitude_path,
                 "also write the service's Attitude (CSV, docs/interfaces.md §2.4)");
  app.add_option("--events", events_path,
                 "also write the service's FdiEvents (JSON lines, docs/interfaces.md §2.5)");
  app.add_option(
      "--commands", commands_path,
      "also write the operator commands the service acknowledged (JSON lines, for replay --commands)");
  app.add_option("--duration", duration_s, "[s] stop after this long")->check(CLI::PositiveNumber);
  app.add_flag("--until-idle", until_idle, "stop when the gyro writers have come and gone");
  add_domain_option(app, domain);
  if (auto exit = parse(app, argc, argv)) return *exit;

  RunFiles files;
  if (!config_path.empty()) files.add_input(config_path, "--config");
  OutputFile* log_out = nullptr;
  OutputFile* attitude_out = nullptr;
  OutputFile* events_out = nullptr;
  OutputFile* commands_out = nullptr;
  if (Status s = files.add_outputs({{out_path, "--out", &log_out},
                                    {attitude_path, "--attitude", &attitude_out},
                                    {events_path, "--events", &events_out},
                                    {commands_path, "--commands", &commands_out}});
      !s)
    return report("record", s.error());

  service::AssemblerConfig assembly;
  if (!config_path.empty()) {
    auto config = service::read_fusion_config(config_path);
    if (!config) return report("record", config.error());
    if (unit.empty()) unit = config->unit;
    assembly = config->assembler(config->calibration.gyro_count());
  } else {
    assembly.gyro_count = gyros;
    assembly.nominal_period_ns = seconds_to_ns(1.0 / rate_hz);
    assembly.tolerance_ns = tolerance_s >= 0 ? seconds_to_ns(tolerance_s) : assembly.nominal_period_ns / 4;
    assembly.max_latency_ns = seconds_to_ns(max_latency_s);
  }
  auto assembler = service::EpochAssembler::create(assembly);
  if (!assembler) return report("record", assembler.error());
  const int n = assembly.gyro_count;

  auto participant = dds::Participant::create(domain, unit);
  if (!participant) return report("record", participant.error());
  auto topics = dds::Topics::create(*participant);
  if (!topics) return report("record", topics.error());
  // Deeper reader histories than the writers': a recorder must not lose what a burst delivers.
  dds::Qos gyro_qos;
  gyro_qos.reliable().volatile_durability().keep_last(4096);
  dds::Qos deep_qos;
  deep_qos.reliable().volatile_durability().keep_last(4096);
  auto attitude_reader = dds::Reader<tetra_Attitude>::create(*participant, topics->attitude, deep_qos);
  if (!attitude_reader) return report("record", attitude_reader.error());
  if (!attitude_path.empty()) {
    // Recording the service's output too: match its Attitude writer before the gyro reader exists,
    // so a simulator waiting for this recorder's gyro reader cannot start before the first attitude
    // can reach us.
    auto matched = dds::WaitSet::create(*participant);
    if (!matched) return report("record", matched.error());
    if (dds_set_status_mask(attitude_reader->handle(), DDS_SUBSCRIPTION_MATCHED_STATUS) < 0 ||
        !matched->attach(attitude_reader->handle(), 1)) {
      return report("record", failure("DDS: cannot wait for the subscription-matched status"));
    }
    const std::int64_t give_up = monotonic_ns() + 10'000'000'000;
    std::vector<std::intptr_t> fired;
    while (*attitude_reader->matched_writers() == 0 && !shutdown.requested()) {
      const std::int64_t now = monotonic_ns();
      if (now >= give_up) {
        std::cerr << "tetra record: no Attitude writer (fusion service) within 10 s; recording anyway\n";
        break;
      }
      if (auto s = matched->wait(std::chrono::nanoseconds(give_up - now), fired); !s)
        return report("record", s.error());
      std::uint32_t status = 0;
      (void)dds_take_status(attitude_reader->handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
    }
  }
  auto gyro_reader = dds::Reader<tetra_GyroSample>::create(*participant, topics->gyro_sample, gyro_qos);
  if (!gyro_reader) return report("record", gyro_reader.error());
  auto reference_reader =
      dds::Reader<tetra_AttitudeReference>::create(*participant, topics->reference, deep_qos);
  if (!reference_reader) return report("record", reference_reader.error());
  auto event_reader = dds::Reader<tetra_FdiEvent>::create(*participant, topics->event, dds::event_qos());
  if (!event_reader) return report("record", event_reader.error());
  auto waitset = dds::WaitSet::create(*participant);
  if (!waitset) return report("record", waitset.error());
  std::vector<dds::Condition> conditions;
  for (dds_entity_t reader : {gyro_reader->handle(), reference_reader->handle(), attitude_reader->handle(),
                              event_reader->handle()}) {
    auto condition = dds::Condition::data_available(reader);
    if (!condition) return report("record", condition.error());
    if (auto s = waitset->attach(condition->handle(), kData); !s) return report("record", s.error());
    conditions.push_back(std::move(condition).value());
  }
  if (auto s = gyro_reader->enable_statuses(DDS_SUBSCRIPTION_MATCHED_STATUS); !s)
    return report("record", s.error());
  if (auto s = waitset->attach(gyro_reader->handle(), kData); !s) return report("record", s.error());
  auto guard = dds::Condition::guard(*participant);
  if (!guard) return report("record", guard.error());
  if (auto s = waitset->attach(guard->handle(), kShutdown); !s) return report("record", s.error());
  shutdown.set_guard(guard->handle());

  GyroLogWriter log;
  bool log_open = false;
  std::string attitude_text = attitude_header(n);
  std::map<std::uint64_t, std::string> event_lines;    // by event_seq: written in order
  std::map<std::uint64_t, std::string> command_lines;  // acknowledgements, by event_seq
  std::vector<fdi::Epoch> epochs;
  std::vector<double> values(static_cast<std::size_t>(n));
  std::optional<std::int64_t> last_epoch_ns;
  std::optional<std::int64_t> last_attitude_ns;
  std::uint64_t epochs_written = 0;
  bool writers_seen = false;
  std::int64_t idle_since = -1;  // [ns] local time the gyro writers went away; -1: not idle
  const std::int64_t start = monotonic_ns();
  const std::int64_t stop_at = duration_s > 0 ? start + seconds_to_ns(duration_s) : INT64_MAX;
  std::vector<std::intptr_t> triggered;

  auto write_epochs = [&]() -> Status {
    for (const auto& epoch : epochs) {
      if (!log_open) {
        if (auto s = log.open(*log_out, n, true, false, record_metadata(unit, files)); !s) return s;
        log_open = true;
      }
      for (int i = 0; i < n; ++i)
        values[static_cast<std::size_t>(i)] = epoch.raw[static_cast<std::size_t>(i)];
      std::optional<std::array<double, 4>> ref;
      if (epoch.reference_q_RB) ref = to_wxyz(*epoch.reference_q_RB);
      if (auto s = log.write(ns_to_seconds(epoch.stamp_ns), values, epoch.present, ref); !s) return s;
      last_epoch_ns = epoch.stamp_ns;
      ++epochs_written;
    }
    epochs.clear();
    return ok_status();
  };

  for (;;) {
    const std::int64_t now = monotonic_ns();
    auto g = gyro_reader->take([&](const tetra_GyroSample& s, const dds_sample_info_t&) {
      const std::string u = dds::from_wire(s.unit);
      if (unit.empty()) {
        unit = u;
        std::cerr << "tetra record: recording unit " << unit << '\n';
      }
      if (u != unit) return;
      (void)assembler->add_sample(s.gyro, s.seq, s.stamp_ns, s.raw, now);
    });
    if (!g) return report("record", g.error());
    auto r = reference_reader->take([&](const tetra_AttitudeReference& s, const dds_sample_info_t&) {
      if (dds::from_wire(s.unit) == unit)
        assembler->add_reference(s.stamp_ns, from_wxyz(s.q_RB[0], s.q_RB[1], s.q_RB[2], s.q_RB[3]));
    });
    if (!r) return report("record", r.error());
    auto a = attitude_reader->take([&](const tetra_Attitude& s, const dds_sample_info_t&) {
      if (dds::from_wire(s.unit) != unit) return;
      const auto attitude = dds::from_wire(s);
      append_attitude_row(attitude_text, ns_to_seconds(attitude.stamp_ns), attitude, n);
      last_attitude_ns = attitude.stamp_ns;
    });
    if (!a) return report("record", a.error());
    auto e = event_reader->take([&](const tetra_FdiEvent& s, const dds_sample_info_t&) {
      const auto view = dds::from_wire(s);
      if (view.unit != unit) return;
      event_lines[view.event_seq] = fdi::to_json(view.event, n);
      if (view.command_id != 0) command_lines[view.event_seq] = ground::ack_json(view, n).dump();
    });
    if (!e) return report("record", e.error());
    assembler->poll(now, epochs);
    if (auto s = write_epochs(); !s) return report("record", s.error());

    std::uint32_t status = 0;
    (void)dds_take_status(gyro_reader->handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
    auto matched = gyro_reader->matched_writers();
    if (!matched) return report("record", matched.error());
    if (*matched > 0) {
      writers_seen = true;
      idle_since = -1;
    } else if (writers_seen && idle_since < 0) {
      idle_since = now;
    }
    if (shutdown.requested() || now >= stop_at) break;
    if (until_idle && idle_since >= 0) {
      // The writers are gone: flush the open epochs, then wait (briefly) for the service's outputs.
      assembler->poll(INT64_MAX, epochs);
      if (auto s = write_epochs(); !s) return report("record", s.error());
      const bool outputs_done =
          attitude_path.empty() || (last_attitude_ns && last_epoch_ns && *last_attitude_ns >= *last_epoch_ns);
      if (outputs_done || now - idle_since >= kIdleGrace_ns) break;
    }
    std::int64_t wake = std::min(stop_at, now + 1'000'000'000);
    if (auto due = assembler->next_due_ns()) wake = std::min(wake, *due);
    if (until_idle && idle_since >= 0) wake = std::min(wake, idle_since + kIdleGrace_ns);
    if (auto s = waitset->wait(std::chrono::nanoseconds(wake - now), triggered); !s)
      return report("record", s.error());
  }
  assembler->poll(INT64_MAX, epochs);
  if (auto s = write_epochs(); !s) return report("record", s.error());
  if (!log_open) {
    if (auto s = log.open(*log_out, n, true, false, record_metadata(unit, files)); !s) {
      return report("record", s.error());
    }
  }
  if (auto s = log.close(); !s) return report("record", s.error());
  if (attitude_out) {
    std::string text;
    for (const auto& [key, value] : record_metadata(unit, files)) append_metadata(text, key, value);
    if (auto s = attitude_out->write(text + attitude_text); !s) return report("record", s.error());
  }
  if (events_out) {
    std::string text;
    for (const auto& [seq, line] : event_lines) text += line + '\n';
    if (auto s = events_out->write(text); !s) return report("record", s.error());
  }
  if (commands_out) {
    std::string text;
    for (const auto& [seq, line] : command_lines) text += line + '\n';
    if (auto s = commands_out->write(text); !s) return report("record", s.error());
  }
  if (auto s = files.commit(); !s) return report("record", s.error());
  const auto& c = assembler->counters();
  std::cerr << "tetra record: " << epochs_written << " epochs of unit "
            << (unit.empty() ? "(none seen)" : unit) << " written to " << out_path << " (late "
            << c.samples_late << ", duplicate " << c.samples_duplicate << ", out of order "
            << c.samples_out_of_order << ", gap " << c.samples_gap << ")\n";
  return kExitOk;
}

}  // namespace tetra::cli
