// tetra replay — the whole fusion pipeline offline: gyro log in; attitude (docs/interfaces.md §2.4) and FDI
// events (docs/interfaces.md §2.5) out; a summary on stderr. The same Pipeline object serves the DDS service.
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include "tetra/report/attitude_csv.hpp"
#include "tetra/report/attitude_writer.hpp"
#include "cli_common.hpp"
#include "tetra/report/command_log.hpp"
#include "commands.hpp"
#include "tetra/report/progress.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/gyro_log_prefetch.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/noise_defaults.hpp"
#include "tetra/fdi/pipeline.hpp"

namespace tetra::cli {

namespace {

using report::AttitudeWriter;
using report::Progress;
using report::RecordedCommand;

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

struct ReplayOptions {
  std::string log_path;
  std::string cal_path;
  std::string config_path;
  std::string attitude_path;
  std::string events_path;
  std::string commands_path;
  std::optional<double> latitude_deg;
  std::optional<std::string> initial_q;
  bool verbose = false;
};

void add_options(CLI::App& app, ReplayOptions& o) {
  app.add_option("LOG", o.log_path, "gyro log (CSV, or HDF5 when named .h5)")->required();
  app.add_option("--calibration", o.cal_path, "calibration file (YAML, docs/interfaces.md §2.3)")->required();
  app.add_option("--latitude", o.latitude_deg,
                 "[deg] ground-test mode: remove the Earth rate at this geodetic latitude")
      ->check(CLI::Range(-90.0, 90.0));
  app.add_option("--initial-q", o.initial_q,
                 "initial attitude w,x,y,z (relative to the lab frame in ground mode), 1 sigma "
                 "pipeline.initial_sigma_deg; the log's first reference sample, if any, sets it instead");
  app.add_option("--config", o.config_path, "YAML file with a 'pipeline:' map of thresholds (docs/fdi.md)");
  app.add_option("--attitude", o.attitude_path, "attitude output (CSV)")->required();
  app.add_option("--events", o.events_path, "FDI events output (JSON lines)")->required();
  app.add_option("--commands", o.commands_path,
                 "operator commands to re-apply where the service obeyed them (JSON lines of tetra record "
                 "--commands)");
  app.add_flag("-v,--verbose", o.verbose, "echo the configuration and the derived thresholds on stderr");
}

// The pipeline's configuration: the --config file, then the options that override it.
Result<fdi::PipelineConfig> pipeline_config(const ReplayOptions& o) {
  fdi::PipelineConfig config;
  if (!o.config_path.empty()) {
    auto c = fdi::read_pipeline_config(o.config_path);
    if (!c) return c.error();
    config = *c;
  }
  if (o.latitude_deg) config.latitude_deg = *o.latitude_deg;
  if (o.initial_q) {
    auto q = parse_quaternion(*o.initial_q);
    if (!q) return q.error();
    config.initial_q_RB = *q;
  }
  return config;
}

struct ReplayInputs {
  Calibration cal;
  std::unique_ptr<GyroLogPrefetcher> log;  // read ahead on a worker thread
  std::vector<RecordedCommand> commands;
};

Result<ReplayInputs> open_inputs(const ReplayOptions& o) {
  ReplayInputs in;
  auto cal = read_calibration(o.cal_path);
  if (!cal) return cal.error();
  in.cal = std::move(cal.value());
  auto opened = GyroLogReader::open(o.log_path);
  if (!opened) return opened.error();
  in.log = std::make_unique<GyroLogPrefetcher>(std::move(opened.value()));
  if (!o.commands_path.empty()) {
    auto c = report::read_command_log(o.commands_path);
    if (!c) return c.error();
    in.commands = std::move(c).value();
  }
  const int gyros = in.log->header().gyro_count;
  if (gyros != in.cal.gyro_count()) {
    return bad_input(o.log_path + ": the log has " + std::to_string(gyros) +
                     " gyro columns, the calibration " + o.cal_path + " has " +
                     std::to_string(in.cal.gyro_count()) + " gyros");
  }
  return in;
}

Result<fdi::Pipeline> make_pipeline(const ReplayOptions& o, const ReplayInputs& in,
                                    fdi::PipelineConfig config) {
  config.raw_units_dps = in.log->header().units_dps;
  if (auto st = fdi::validate(config); !st) return st.error();
  auto pipeline = fdi::Pipeline::create(in.cal, config);
  if (!pipeline) return bad_input(o.cal_path + ": " + pipeline.error().message);
  if (o.verbose) std::fprintf(stderr, "tetra replay: configuration\n%s", fdi::describe(config).c_str());
  return pipeline;
}

struct Replayed {
  std::size_t epochs = 0;                   // epochs read
  std::map<std::string, int> event_counts;  // per event type
};

// Feeds one block's epochs to the pipeline; accepted attitudes go to `att`, events to `events`.
// `before_epoch` applies the recorded commands due before an epoch's stamp.
template <class BeforeEpoch>
Status replay_block(const GyroLog& block, fdi::Pipeline& pipeline, fdi::Epoch& epoch,
                    BeforeEpoch before_epoch, AttitudeWriter& att, BufferedOutput& events, Replayed& out) {
  const auto ng = static_cast<std::size_t>(block.gyro_count);
  for (std::size_t k = 0; k < block.epochs(); ++k) {
    epoch.stamp_ns = seconds_to_ns(block.time_s[k]);
    for (std::size_t i = 0; i < ng; ++i) {
      epoch.raw[i] = block.values[k * ng + i];
      epoch.present[i] = block.present[k * ng + i] != 0 ? 1 : 0;
    }
    before_epoch(epoch.stamp_ns);
    epoch.reference_q_RB.reset();
    if (block.has_reference && block.reference_present[k] != 0)
      epoch.reference_q_RB = from_wxyz(block.reference_wxyz[k]);
    const auto& r = pipeline.step(epoch);
    for (const auto& e : r.events) {
      events.buffer() += fdi::to_json(e, block.gyro_count);
      events.buffer() += '\n';
      ++out.event_counts[fdi::to_string(e.type)];
    }
    if (!r.accepted) continue;
    if (Status s = att.add(block.time_s[k], r.attitude); !s) return s;  // the log's own time, bit for bit
  }
  out.epochs += block.epochs();
  return events.maybe_flush();
}

// The pipeline over the log as it is read, block by block; attitude rows and events are appended to
// the outputs as they come, so memory does not grow with the log's length.
// Recorded operator commands are applied where the service obeyed them: after the last epoch before
// their stamp, each acknowledgement written before that epoch's own events.
Result<Replayed> replay_log(GyroLogPrefetcher& log, fdi::Pipeline& pipeline,
                            const std::vector<RecordedCommand>& commands, AttitudeWriter& att,
                            BufferedOutput& events) {
  const int n = log.header().gyro_count;
  std::size_t next_command = 0;
  auto apply_commands_before = [&](std::int64_t stamp_ns, bool all) {
    for (; next_command < commands.size() && (all || commands[next_command].stamp_ns < stamp_ns);
         ++next_command) {
      events.buffer() += fdi::to_json(report::apply(pipeline, commands[next_command]), n);
      events.buffer() += '\n';
    }
  };
  Replayed out;
  fdi::Epoch epoch;
  epoch.raw.resize(static_cast<std::size_t>(n));
  epoch.present.resize(static_cast<std::size_t>(n));
  Progress progress("tetra replay", "epochs", ::isatty(STDERR_FILENO) == 1 ? stderr : nullptr);
  GyroLog block;
  while (true) {
    auto more = log.next(block);
    if (!more) return more.error();
    if (!*more) break;
    const auto before = [&](std::int64_t stamp_ns) { apply_commands_before(stamp_ns, false); };
    if (Status s = replay_block(block, pipeline, epoch, before, att, events, out); !s) return s.error();
    progress.update(log.fraction_read(), out.epochs);
  }
  // Commands after the last epoch: acknowledged (their other effects would show on a next epoch).
  apply_commands_before(0, true);
  progress.finish();
  return out;
}

void print_summary(const fdi::Pipeline& pipeline, const Replayed& replayed, int n) {
  const auto& h = pipeline.health();
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
  for (const auto& [name, count] : replayed.event_counts)
    ev += (ev.empty() ? "" : ", ") + name + " " + std::to_string(count);
  std::fprintf(
      stderr,
      "tetra replay: %zu epochs read, %llu accepted; rejected: %llu time not increasing, %llu time "
      "outliers, %llu wrong sample count\n"
      "  samples: %llu accepted, %llu invalid, %llu absent, %llu outliers left out (%llu spikes)\n"
      "  events: %s\n"
      "  final mode: %s, gyros used: %s, excluded: %s\n",
      replayed.epochs, static_cast<unsigned long long>(c.epochs_accepted),
      static_cast<unsigned long long>(c.epochs_rejected_time),
      static_cast<unsigned long long>(c.epochs_time_outlier),
      static_cast<unsigned long long>(c.epochs_rejected_shape),
      static_cast<unsigned long long>(c.samples_accepted), static_cast<unsigned long long>(c.samples_invalid),
      static_cast<unsigned long long>(c.samples_absent), static_cast<unsigned long long>(c.samples_outlier),
      static_cast<unsigned long long>(c.spikes), ev.empty() ? "none" : ev.c_str(), fdi::to_string(h.mode),
      mask_to_string(h.used, n).c_str(), excluded.empty() ? "none" : excluded.c_str());
  // Most of the log left out is never a quiet success: the exit status stays 0 (the outputs are what the
  // pipeline made of the log), the warning says what was lost.
  const std::uint64_t rejected = c.epochs_rejected_time + c.epochs_time_outlier + c.epochs_rejected_shape;
  if (replayed.epochs > 0 && 2 * rejected > replayed.epochs) {
    std::fprintf(stderr,
                 "tetra replay: warning: %llu of %zu epochs rejected (%llu time not increasing, %llu time "
                 "outliers, %llu wrong sample count): the attitude covers only part of the log\n",
                 static_cast<unsigned long long>(rejected), replayed.epochs,
                 static_cast<unsigned long long>(c.epochs_rejected_time),
                 static_cast<unsigned long long>(c.epochs_time_outlier),
                 static_cast<unsigned long long>(c.epochs_rejected_shape));
  }
}

// Outputs, configuration, inputs, pipeline; the replay; the outputs committed; the summary.
Status run_replay(const ReplayOptions& o) {
  RunFiles files;
  files.add_input(o.log_path, "LOG");
  files.add_input(o.cal_path, "--calibration");
  if (!o.config_path.empty()) files.add_input(o.config_path, "--config");
  if (!o.commands_path.empty()) files.add_input(o.commands_path, "--commands");
  auto attitude_out = files.add(o.attitude_path, "--attitude");
  if (!attitude_out) return attitude_out.error();
  auto events_out = files.add(o.events_path, "--events");
  if (!events_out) return events_out.error();
  auto config = pipeline_config(o);
  if (!config) return config.error();
  auto in = open_inputs(o);
  if (!in) return in.error();
  auto pipeline = make_pipeline(o, *in, *config);
  if (!pipeline) return pipeline.error();

  const int n = in->cal.gyro_count();
  std::string preamble;
  for (const auto& [key, value] : provenance_metadata(provenance(files.input_paths())))
    append_metadata(preamble, key, value);
  preamble += report::attitude_header(n);
  AttitudeWriter att(**attitude_out, n, std::move(preamble));
  BufferedOutput events(**events_out);
  auto replayed = replay_log(*in->log, *pipeline, in->commands, att, events);
  if (!replayed) return replayed.error();
  if (Status st = att.finish(); !st) return st;
  if (Status st = events.flush(); !st) return st;
  if (Status st = files.commit(); !st) return st;
  if (o.verbose)
    std::fprintf(stderr, "tetra replay: thresholds\n%s", pipeline->describe_thresholds().c_str());
  print_summary(*pipeline, *replayed, n);
  // Last, where it stays in view (and a run that fails says its one error line alone).
  if (const std::string w = fdi::default_noise_warning(in->cal, *config); !w.empty())
    std::fprintf(stderr, "tetra replay: warning: %s: %s\n", o.cal_path.c_str(), w.c_str());
  return ok_status();
}

}  // namespace

int cmd_replay(int argc, char** argv) {
  CLI::App app{
      "Run the fusion and fault-detection pipeline over a gyro log (docs/interfaces.md §2.2): writes the "
      "attitude (§2.4) and the FDI events (§2.5); prints a summary on stderr.",
      "replay"};
  ReplayOptions options;
  add_options(app, options);
  if (auto status = parse(app, argc, argv)) return *status;
  if (Status s = run_replay(options); !s) return report("replay", s.error());
  return kExitOk;
}

}  // namespace tetra::cli
