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
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
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
  app.add_option("LOG", log_path, "gyro log (CSV)")->required();
  app.add_option("--calibration", cal_path, "calibration file (YAML, docs/interfaces.md §2.3)")->required();
  app.add_option("--latitude", latitude_deg,
                 "[deg] ground-test mode: remove the Earth rate at this geodetic latitude")
      ->check(CLI::Range(-90.0, 90.0));
  app.add_option("--initial-q", initial_q,
                 "initial attitude w,x,y,z (relative to the lab frame in ground mode)");
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
  auto log = read_gyro_log(log_path);
  if (!log) return report("replay", log.error());
  std::vector<RecordedCommand> commands;
  if (!commands_path.empty()) {
    auto c = read_command_log(commands_path);
    if (!c) return report("replay", c.error());
    commands = std::move(c).value();
  }
  std::size_t next_command = 0;
  if (log->gyro_count != cal->gyro_count()) {
    return report("replay", bad_input(log_path + ": the log has " + std::to_string(log->gyro_count) +
                                      " gyro columns, the calibration " + cal_path + " has " +
                                      std::to_string(cal->gyro_count()) + " gyros"));
  }
  config.raw_units_dps = log->units_dps;
  if (auto st = fdi::validate(config); !st) return report("replay", st.error());
  auto pipeline = fdi::Pipeline::create(*cal, config);
  if (!pipeline) {
    return report("replay", bad_input(cal_path + ": " + pipeline.error().message));
  }

  if (verbose) {
    std::fprintf(stderr, "tetra replay: configuration\n%s", fdi::describe(config).c_str());
  }
  const int n = log->gyro_count;
  std::string att;
  att.reserve(log->epochs() * 160 + 1024);
  for (const auto& [key, value] : provenance_metadata(provenance(files.input_paths())))
    append_metadata(att, key, value);
  att += kAttitudeHeader;
  std::string events;
  std::map<std::string, int> event_counts;
  fdi::Epoch epoch;
  epoch.raw.resize(static_cast<std::size_t>(n));
  epoch.present.resize(static_cast<std::size_t>(n));
  // Progress on stderr for long logs (a 100-min 10 Hz orbit takes about 0.1 s and prints nothing).
  const std::size_t progress_every = log->epochs() >= 2'000'000 ? log->epochs() / 10 : 0;
  for (std::size_t k = 0; k < log->epochs(); ++k) {
    if (progress_every != 0 && k != 0 && k % progress_every == 0) {
      std::fprintf(stderr, "tetra replay: %zu%% (%zu epochs)\n", 100 * k / log->epochs(), k);
    }
    epoch.stamp_ns = seconds_to_ns(log->time_s[k]);
    for (int i = 0; i < n; ++i) {
      epoch.raw[static_cast<std::size_t>(i)] = log->value(k, i);
      epoch.present[static_cast<std::size_t>(i)] = log->is_present(k, i) ? 1 : 0;
    }
    // Commands the service obeyed after the last epoch before this one: the same place in the stream.
    // Each acknowledgement is written where the service published it: before the epoch's own events.
    for (; next_command < commands.size() && commands[next_command].stamp_ns < epoch.stamp_ns;
         ++next_command) {
      events += fdi::to_json(apply(*pipeline, commands[next_command]), n);
      events += '\n';
    }
    epoch.reference_q_RB.reset();
    if (log->has_reference && log->reference_present[k] != 0)
      epoch.reference_q_RB = from_wxyz(log->reference_wxyz[k]);
    const auto& r = pipeline->step(epoch);
    for (const auto& e : r.events) {
      events += fdi::to_json(e, n);
      events += '\n';
      ++event_counts[fdi::to_string(e.type)];
    }
    if (!r.accepted) continue;
    append_attitude_row(att, log->time_s[k], r.attitude, n);  // the log's own time, bit for bit
  }
  // Commands after the last epoch: acknowledged (their other effects would show on a next epoch).
  for (; next_command < commands.size(); ++next_command) {
    events += fdi::to_json(apply(*pipeline, commands[next_command]), n);
    events += '\n';
  }
  if (auto st = (*attitude_out)->write(att); !st) return report("replay", st.error());
  if (auto st = (*events_out)->write(events); !st) return report("replay", st.error());
  if (auto st = files.commit(); !st) return report("replay", st.error());

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
      log->epochs(), static_cast<unsigned long long>(c.epochs_accepted),
      static_cast<unsigned long long>(c.epochs_rejected_time),
      static_cast<unsigned long long>(c.epochs_rejected_shape),
      static_cast<unsigned long long>(c.samples_accepted), static_cast<unsigned long long>(c.samples_invalid),
      static_cast<unsigned long long>(c.samples_absent), static_cast<unsigned long long>(c.samples_outlier),
      static_cast<unsigned long long>(c.spikes), ev.empty() ? "none" : ev.c_str(), fdi::to_string(h.mode),
      mask_to_string(h.used, n).c_str(), excluded.empty() ? "none" : excluded.c_str());
  return kExitOk;
}

}  // namespace tetra::cli
