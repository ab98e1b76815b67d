// Replay of a gyro log through the fusion pipeline (tetra/report/replay_log.hpp).
#include "tetra/report/replay_log.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

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
#include "tetra/report/attitude_csv.hpp"
#include "tetra/report/attitude_writer.hpp"
#include "tetra/report/command_log.hpp"
#include "tetra/report/ledger_explainer.hpp"
#include "tetra/report/progress.hpp"
#include "tetra/report/text.hpp"

namespace tetra::report {

namespace {

Result<Quaternion> parse_quaternion(const std::string& text) {
  std::array<double, 4> q{};
  std::stringstream ss(text);
  std::string item;
  std::size_t n = 0;
  while (std::getline(ss, item, ',')) {
    if (n >= 4) return bad_input(ErrorSubject(kSubjectInitialQ), "expected four numbers w,x,y,z, got more");
    const auto v = parse_decimal(item);
    if (!v) return bad_input(ErrorSubject(kSubjectInitialQ), "'" + item + "' is not a decimal number");
    q[n] = *v;
    ++n;
  }
  if (n != 4) return bad_input(ErrorSubject(kSubjectInitialQ), "expected four numbers w,x,y,z");
  const Quaternion quat = from_wxyz(q);
  if (!std::isfinite(quat.norm()) || std::abs(quat.norm() - 1.0) > 1e-3) {
    return bad_input(ErrorSubject(kSubjectInitialQ), "not a unit quaternion (norm must be 1 within 1e-3)");
  }
  return quat.normalized();
}

// The pipeline's configuration: the --config file, then the options that override it.
Result<fdi::PipelineConfig> pipeline_config(const ReplayLogOptions& o) {
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

Result<ReplayInputs> open_inputs(const ReplayLogOptions& o) {
  ReplayInputs in;
  auto cal = read_calibration(o.calibration_path);
  if (!cal) return cal.error();
  in.cal = std::move(cal.value());
  auto opened = GyroLogReader::open(o.log_path);
  if (!opened) return opened.error();
  in.log = std::make_unique<GyroLogPrefetcher>(std::move(opened.value()));
  if (!o.commands_path.empty()) {
    auto c = read_command_log(o.commands_path);
    if (!c) return c.error();
    in.commands = std::move(c).value();
  }
  const int gyros = in.log->header().gyro_count;
  if (gyros != in.cal.gyro_count()) {
    return bad_input(o.log_path + ": the log has " + std::to_string(gyros) +
                     " gyro columns, the calibration " + o.calibration_path + " has " +
                     std::to_string(in.cal.gyro_count()) + " gyros");
  }
  return in;
}

Result<fdi::Pipeline> make_pipeline(const ReplayLogOptions& o, const ReplayInputs& in,
                                    fdi::PipelineConfig config, std::ostream& err) {
  config.raw_units_dps = in.log->header().units_dps;
  if (auto st = fdi::validate(config); !st) return st.error();
  auto pipeline = fdi::Pipeline::create(in.cal, config);
  if (!pipeline) return bad_input(o.calibration_path + ": " + pipeline.error().message);
  if (o.verbose) err << name_of(o.names, "command") << ": configuration\n" << fdi::describe(config);
  return pipeline;
}

// Feeds one block's epochs to the pipeline; accepted attitudes go to `att`, events to `events`.
// `before_epoch` applies the recorded commands due before an epoch's stamp.
template <class BeforeEpoch>
Status replay_block(const GyroLog& block, fdi::Pipeline& pipeline, fdi::Epoch& epoch,
                    BeforeEpoch before_epoch, AttitudeWriter& att, BufferedOutput& events, ReplayedLog& out) {
  const auto ng = static_cast<std::size_t>(block.gyro_count);
  for (std::size_t k = 0; k < block.epochs(); ++k) {
    epoch.stamp_ns = seconds_to_ns(block.time_s[k]);
    for (std::size_t i = 0; i < ng; ++i) {
      epoch.raw[i] = block.values[k * ng + i];
      epoch.present[i] = block.present[k * ng + i] != 0 ? 1 : 0;
    }
    before_epoch(epoch.stamp_ns);
    epoch.reference_q_RB.reset();
    epoch.reference_stamp_ns.reset();
    if (block.has_reference && block.reference_present[k] != 0)
      epoch.reference_q_RB = from_wxyz(block.reference_wxyz[k]);
    // A reference taken before its row (a late star tracker, as recorded): fused at its own time, as the
    // service did.
    if (block.has_reference_stamp && std::isfinite(block.reference_stamp_s[k]))
      epoch.reference_stamp_ns = seconds_to_ns(block.reference_stamp_s[k]);
    const auto& r = pipeline.step(epoch);
    if (out.explainer) out.explainer->observe(block.time_s[k], r, pipeline);
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
Result<ReplayedLog> replay_blocks(GyroLogPrefetcher& log, fdi::Pipeline& pipeline,
                                  const std::vector<RecordedCommand>& commands, AttitudeWriter& att,
                                  BufferedOutput& events, std::FILE* terminal,
                                  std::optional<double> explain_s) {
  const int n = log.header().gyro_count;
  std::size_t next_command = 0;
  auto apply_commands_before = [&](std::int64_t stamp_ns, bool all) {
    for (; next_command < commands.size() && (all || commands[next_command].stamp_ns < stamp_ns);
         ++next_command) {
      events.buffer() += fdi::to_json(apply(pipeline, commands[next_command]), n);
      events.buffer() += '\n';
    }
  };
  ReplayedLog out;
  if (explain_s) out.explainer.emplace(*explain_s);
  fdi::Epoch epoch;
  epoch.raw.resize(static_cast<std::size_t>(n));
  epoch.present.resize(static_cast<std::size_t>(n));
  Progress progress("tetra replay", "epochs", terminal);
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

void print_summary(std::ostream& err, const std::string& command, const fdi::Pipeline& pipeline,
                   const ReplayedLog& replayed, int n) {
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
  err << command
      << printf_text(
             ": %zu epochs read, %llu accepted; rejected: %llu time not increasing, %llu time "
             "outliers, %llu wrong sample count\n"
             "  samples: %llu accepted, %llu invalid, %llu absent, %llu outliers left out (%llu spikes)\n"
             "  events: %s\n"
             "  final mode: %s, gyros used: %s, excluded: %s\n",
             replayed.epochs, static_cast<unsigned long long>(c.epochs_accepted),
             static_cast<unsigned long long>(c.epochs_rejected_time),
             static_cast<unsigned long long>(c.epochs_time_outlier),
             static_cast<unsigned long long>(c.epochs_rejected_shape),
             static_cast<unsigned long long>(c.samples_accepted),
             static_cast<unsigned long long>(c.samples_invalid),
             static_cast<unsigned long long>(c.samples_absent),
             static_cast<unsigned long long>(c.samples_outlier), static_cast<unsigned long long>(c.spikes),
             ev.empty() ? "none" : ev.c_str(), fdi::to_string(h.mode), mask_to_string(h.used, n).c_str(),
             excluded.empty() ? "none" : excluded.c_str());
  if (const auto it = replayed.event_counts.find("calibration_mismatch"); it != replayed.event_counts.end())
    err << command
        << ": warning: the calibration does not describe this unit (calibration_mismatch: the parity follows "
           "the body rate as no single gyro's fault makes it): sigma does not cover it and the parity's "
           "evidence excluded nothing; calibrate the unit (tetra calibrate)\n";
  // Most of the log left out is never a quiet success: the exit status stays 0 (the outputs are what the
  // pipeline made of the log), the warning says what was lost.
  const std::uint64_t rejected = c.epochs_rejected_time + c.epochs_time_outlier + c.epochs_rejected_shape;
  if (replayed.epochs > 0 && 2 * rejected > replayed.epochs) {
    err << command
        << printf_text(
               ": warning: %llu of %zu epochs rejected (%llu time not increasing, %llu time "
               "outliers, %llu wrong sample count): the attitude covers only part of the log\n",
               static_cast<unsigned long long>(rejected), replayed.epochs,
               static_cast<unsigned long long>(c.epochs_rejected_time),
               static_cast<unsigned long long>(c.epochs_time_outlier),
               static_cast<unsigned long long>(c.epochs_rejected_shape));
  }
}

}  // namespace

Result<ReplayedLog> replay_log(const ReplayLogOptions& o, std::ostream& err) {
  RunFiles files;
  files.add_input(o.log_path, name_of(o.names, "log_path"));
  files.add_input(o.calibration_path, name_of(o.names, "calibration_path"));
  if (!o.config_path.empty()) files.add_input(o.config_path, name_of(o.names, "config_path"));
  if (!o.commands_path.empty()) files.add_input(o.commands_path, name_of(o.names, "commands_path"));
  auto attitude_out = files.add(o.attitude_path, name_of(o.names, "attitude_path"));
  if (!attitude_out) return attitude_out.error();
  auto events_out = files.add(o.events_path, name_of(o.names, "events_path"));
  if (!events_out) return events_out.error();
  auto config = pipeline_config(o);
  if (!config) return config.error();
  auto in = open_inputs(o);
  if (!in) return in.error();
  auto pipeline = make_pipeline(o, *in, *config, err);
  if (!pipeline) return pipeline.error();

  const int n = in->cal.gyro_count();
  std::string preamble;
  for (const auto& [key, value] : provenance_metadata(provenance(files.input_paths())))
    append_metadata(preamble, key, value);
  preamble += attitude_header(n);
  AttitudeWriter att(**attitude_out, n, std::move(preamble));
  BufferedOutput events(**events_out);
  auto replayed =
      replay_blocks(*in->log, *pipeline, in->commands, att, events, o.progress_terminal, o.explain_s);
  if (!replayed) return replayed.error();
  if (Status st = att.finish(); !st) return st.error();
  if (Status st = events.flush(); !st) return st.error();
  if (Status st = files.commit(); !st) return st.error();
  const std::string command = name_of(o.names, "command");
  if (o.verbose) err << command << ": thresholds\n" << pipeline->describe_thresholds();
  print_summary(err, command, *pipeline, *replayed, n);
  // Last, where it stays in view (and a run that fails says its one error line alone).
  if (const std::string w = fdi::default_noise_warning(in->cal, *config); !w.empty())
    err << command << ": warning: " << o.calibration_path << ": " << w << "\n";
  replayed->health = pipeline->health();
  if (replayed->explainer) replayed->explanation = replayed->explainer->text(n);
  return replayed;
}

}  // namespace tetra::report
