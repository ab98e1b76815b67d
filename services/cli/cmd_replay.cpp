// tetra replay — the whole fusion pipeline offline: gyro log in; attitude (docs/interfaces.md §2.4) and FDI
// events (docs/interfaces.md §2.5) out; a summary on stderr. The same Pipeline object serves the DDS service.
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include "attitude_csv.hpp"
#include "cli_common.hpp"
#include "command_log.hpp"
#include "commands.hpp"
#include "progress.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/gyro_log_prefetch.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/pipeline.hpp"

namespace tetra::cli {

namespace {

Result<Quaternion> parse_quaternion(const std::string& text) {
  std::array<double, 4> q{};
  std::stringstream ss(text);
  std::string item;
  std::size_t n = 0;
  while (std::getline(ss, item, ',')) {
    if (n >= 4) return bad_input("--initial-q: expected four numbers w,x,y,z, got more");
    const auto v = parse_decimal(item);
    if (!v) return bad_input("--initial-q: '" + item + "' is not a decimal number");
    q[n] = *v;
    ++n;
  }
  if (n != 4) return bad_input("--initial-q: expected four numbers w,x,y,z");
  const Quaternion quat = from_wxyz(q);
  if (!std::isfinite(quat.norm()) || std::abs(quat.norm() - 1.0) > 1e-3) {
    return bad_input("--initial-q: not a unit quaternion (norm must be 1 within 1e-3)");
  }
  return quat.normalized();
}

struct Replayed {
  std::size_t epochs = 0;                   // epochs read
  std::map<std::string, int> event_counts;  // per event type
};

// The pipeline over the log as it is read, block by block; attitude rows and events are appended to
// the outputs as they come, so memory does not grow with the log's length.
// Recorded operator commands are applied where the service obeyed them: after the last epoch before
// their stamp, each acknowledgement written before that epoch's own events.
Result<Replayed> replay_log(GyroLogPrefetcher& log, fdi::Pipeline& pipeline,
                            const std::vector<RecordedCommand>& commands, BufferedOutput& att,
                            BufferedOutput& events) {
  const int n = log.header().gyro_count;
  const auto ng = static_cast<std::size_t>(n);
  std::size_t next_command = 0;
  auto apply_commands_before = [&](std::int64_t stamp_ns, bool all) {
    for (; next_command < commands.size() && (all || commands[next_command].stamp_ns < stamp_ns);
         ++next_command) {
      events.buffer() += fdi::to_json(apply(pipeline, commands[next_command]), n);
      events.buffer() += '\n';
    }
  };
  Replayed out;
  fdi::Epoch epoch;
  epoch.raw.resize(ng);
  epoch.present.resize(ng);
  Progress progress("tetra replay", "epochs");
  GyroLog block;
  while (true) {
    auto more = log.next(block);
    if (!more) return more.error();
    if (!*more) break;
    for (std::size_t k = 0; k < block.epochs(); ++k) {
      epoch.stamp_ns = seconds_to_ns(block.time_s[k]);
      for (std::size_t i = 0; i < ng; ++i) {
        epoch.raw[i] = block.values[k * ng + i];
        epoch.present[i] = block.present[k * ng + i] != 0 ? 1 : 0;
      }
      apply_commands_before(epoch.stamp_ns, false);
      epoch.reference_q_RB.reset();
      if (block.has_reference && block.reference_present[k] != 0)
        epoch.reference_q_RB = from_wxyz(block.reference_wxyz[k]);
      const auto& r = pipeline.step(epoch);
      for (const auto& e : r.events) {
        events.buffer() += fdi::to_json(e, n);
        events.buffer() += '\n';
        ++out.event_counts[fdi::to_string(e.type)];
      }
      if (!r.accepted) continue;
      append_attitude_row(att.buffer(), block.time_s[k], r.attitude, n);  // the log's own time, bit for bit
    }
    out.epochs += block.epochs();
    if (auto st = att.maybe_flush(); !st) return st.error();
    if (auto st = events.maybe_flush(); !st) return st.error();
    progress.update(log.fraction_read(), out.epochs);
  }
  // Commands after the last epoch: acknowledged (their other effects would show on a next epoch).
  apply_commands_before(0, true);
  progress.finish();
  return out;
}

}  // namespace

int cmd_replay(int argc, char** argv) {
  CLI::App app{
      "Run the fusion and fault-detection pipeline over a gyro log (docs/interfaces.md §2.2): writes the "
      "attitude (§2.4) and the FDI events (§2.5); prints a summary on stderr.",
      "replay"};
  std::string log_path;
  std::string cal_path;
  std::string config_path;
  std::string attitude_path;
  std::string events_path;
  std::optional<double> latitude_deg;
  std::string initial_q;
  app.add_option("LOG", log_path, "gyro log (CSV, or HDF5 when named .h5)")->required();
  app.add_option("--calibration", cal_path, "calibration file (YAML, docs/interfaces.md §2.3)")->required();
  app.add_option("--latitude", latitude_deg,
                 "[deg] ground-test mode: remove the Earth rate at this geodetic latitude")
      ->check(CLI::Range(-90.0, 90.0));
  app.add_option("--initial-q", initial_q,
                 "initial attitude w,x,y,z (relative to the lab frame in ground mode), 1 sigma "
                 "pipeline.initial_sigma_deg; the log's first reference sample, if any, sets it instead");
  app.add_option("--config", config_path, "YAML file with a 'pipeline:' map of thresholds (docs/fdi.md)");
  app.add_option("--attitude", attitude_path, "attitude output (CSV)")->required();
  app.add_option("--events", events_path, "FDI events output (JSON lines)")->required();
  std::string commands_path;
  app.add_option("--commands", commands_path,
                 "operator commands to re-apply where the service obeyed them (JSON lines of tetra record "
                 "--commands)");
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "echo the configuration and the derived thresholds on stderr");
  if (auto status = parse(app, argc, argv)) return *status;

  RunFiles files;
  files.add_input(log_path, "LOG");
  files.add_input(cal_path, "--calibration");
  if (!config_path.empty()) files.add_input(config_path, "--config");
  if (!commands_path.empty()) files.add_input(commands_path, "--commands");
  auto attitude_out = files.add(attitude_path, "--attitude");
  if (!attitude_out) return report("replay", attitude_out.error());
  auto events_out = files.add(events_path, "--events");
  if (!events_out) return report("replay", events_out.error());

  fdi::PipelineConfig config;
  if (!config_path.empty()) {
    auto c = fdi::read_pipeline_config(config_path);
    if (!c) return report("replay", c.error());
    config = *c;
  }
  if (latitude_deg) config.latitude_deg = *latitude_deg;
  if (!initial_q.empty()) {
    auto q = parse_quaternion(initial_q);
    if (!q) return report("replay", q.error());
    config.initial_q_RB = *q;
  }

  auto cal = read_calibration(cal_path);
  if (!cal) return report("replay", cal.error());
  auto opened = GyroLogReader::open(log_path);
  if (!opened) return report("replay", opened.error());
  GyroLogPrefetcher log(std::move(opened.value()));
  const GyroLog& head = log.header();
  std::vector<RecordedCommand> commands;
  if (!commands_path.empty()) {
    auto c = read_command_log(commands_path);
    if (!c) return report("replay", c.error());
    commands = std::move(c).value();
  }
  if (head.gyro_count != cal->gyro_count()) {
    return report("replay", bad_input(log_path + ": the log has " + std::to_string(head.gyro_count) +
                                      " gyro columns, the calibration " + cal_path + " has " +
                                      std::to_string(cal->gyro_count()) + " gyros"));
  }
  config.raw_units_dps = head.units_dps;
  if (auto st = fdi::validate(config); !st) return report("replay", st.error());
  auto pipeline = fdi::Pipeline::create(*cal, config);
  if (!pipeline) {
    return report("replay", bad_input(cal_path + ": " + pipeline.error().message));
  }

  if (verbose) {
    std::fprintf(stderr, "tetra replay: configuration\n%s", fdi::describe(config).c_str());
  }
  BufferedOutput att(**attitude_out);
  BufferedOutput events(**events_out);
  for (const auto& [key, value] : provenance_metadata(provenance(files.input_paths())))
    append_metadata(att.buffer(), key, value);
  att.buffer() += attitude_header(pipeline->gyro_count());
  auto replayed = replay_log(log, *pipeline, commands, att, events);
  if (!replayed) return report("replay", replayed.error());
  if (auto st = att.flush(); !st) return report("replay", st.error());
  if (auto st = events.flush(); !st) return report("replay", st.error());
  if (auto st = files.commit(); !st) return report("replay", st.error());
  const std::size_t epochs_read = replayed->epochs;
  const std::map<std::string, int>& event_counts = replayed->event_counts;
  const int n = head.gyro_count;

  if (verbose) std::fprintf(stderr, "tetra replay: thresholds\n%s", pipeline->describe_thresholds().c_str());
  const auto& h = pipeline->health();
  const auto& c = h.counters;
  std::string excluded;
  for (int i = 0; i < n; ++i) {
    const auto& g = h.gyros[static_cast<std::size_t>(i)];
    if (g.state == fdi::GyroState::kExcluded) {
      excluded +=
          (excluded.empty() ? "" : ", ") + std::to_string(i + 1) + " (" + fdi::to_string(g.kind) + ")";
    }
  }
  std::string ev;
  for (const auto& [name, count] : event_counts)
    ev += (ev.empty() ? "" : ", ") + name + " " + std::to_string(count);
  std::fprintf(
      stderr,
      "tetra replay: %zu epochs read, %llu accepted; rejected: %llu time not increasing, %llu wrong "
      "sample count\n"
      "  samples: %llu accepted, %llu invalid, %llu absent, %llu outliers left out (%llu spikes)\n"
      "  events: %s\n"
      "  final mode: %s, gyros used: %s, excluded: %s\n",
      epochs_read, static_cast<unsigned long long>(c.epochs_accepted),
      static_cast<unsigned long long>(c.epochs_rejected_time),
      static_cast<unsigned long long>(c.epochs_rejected_shape),
      static_cast<unsigned long long>(c.samples_accepted), static_cast<unsigned long long>(c.samples_invalid),
      static_cast<unsigned long long>(c.samples_absent), static_cast<unsigned long long>(c.samples_outlier),
      static_cast<unsigned long long>(c.spikes), ev.empty() ? "none" : ev.c_str(), fdi::to_string(h.mode),
      mask_to_string(h.used, n).c_str(), excluded.empty() ? "none" : excluded.c_str());
  return kExitOk;
}

}  // namespace tetra::cli
