#include "tetra/report/closed_loop_files.hpp"

#include <spdlog/fmt/fmt.h>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/report/pointing_plot.hpp"
#include "tetra/sim/pointing_report.hpp"

namespace tetra::report {

namespace {

std::string dec(double value, int decimals) {
  return fmt::format("{:.{}f}", value, decimals);
}

struct LoopRun {
  sim::ClosedLoopRecord record;
  sim::PointingSummary summary;
};

Result<LoopRun> run_once(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                         const Calibration& calibration, const fdi::PipelineConfig& config) {
  auto simulator = sim::ClosedLoopSimulator::create(scenario, sim_options);
  if (!simulator) return simulator.error();
  auto estimator = sim::PipelineEstimator::create(calibration, config, simulator->initial_q_NB());
  if (!estimator) return estimator.error();
  auto record = sim::run_closed_loop(*simulator, *estimator);
  if (!record) return record.error();
  LoopRun run{std::move(record.value()), {}};
  run.summary = sim::summarize(run.record, *simulator);
  return run;
}

std::string opt_text(const std::optional<double>& v, int digits) {
  return v ? dec(*v, digits) + " s" : std::string("never");
}

void print_loop_summary(std::ostream& out, const std::string& label, const sim::PointingSummary& s,
                        const sim::ClosedLoopRecord& record) {
  out << label << "pointing error rms " << dec(s.rms_deg, 5) << " deg, max " << dec(s.max_deg, 5)
      << " deg (bound " << dec(s.bound_deg, 4) << " deg), final " << dec(s.final_error_deg, 5) << " deg\n";
  for (const sim::PointingSegment& g : s.segments) {
    out << label << "  " << g.label << " [" << dec(g.from_s, 1) << ", " << dec(g.to_s, 1) << ") s: rms "
        << dec(g.rms_deg, 5) << " deg, max " << dec(g.max_deg, 5) << " deg, "
        << (g.recover_s ? "recovered after " + dec(*g.recover_s, 1) + " s" : "NOT recovered") << '\n';
  }
  if (record.fdi_events) {
    out << label << "fdi: " << sim::outcome_name(s.fdi.outcome) << ", detection "
        << opt_text(s.fdi.detection_delay_s, 2) << ", isolation " << opt_text(s.fdi.isolation_delay_s, 2)
        << ", false alarms " << s.fdi.false_alarms << '\n';
  }
  out << label << "wheels: max momentum " << dec(100.0 * s.max_wheel_momentum_fraction, 1)
      << " % of the limit, torque-limited " << dec(s.torque_limited_s, 1) << " s; control: hold "
      << s.counters.hold_epochs << " epochs, safe " << s.counters.safe_epochs << " epochs ("
      << s.counters.safe_entries << " entries, " << s.counters.lost_epochs
      << " on a lost attitude); estimate age mean " << dec(s.mean_estimate_age_s, 4) << " s, max "
      << dec(s.max_estimate_age_s, 3) << " s; estimates of their own epoch " << record.estimates_received
      << " of " << record.series.size() << "; run " << dec(record.wall_s, 2) << " s\n";
}

std::vector<double> onsets_of(const sim::PointingSummary& s) {
  std::vector<double> onsets;
  for (std::size_t i = 1; i < s.segments.size(); ++i) onsets.push_back(s.segments[i].from_s);
  return onsets;
}

Status write_loop_outputs(const sim::Scenario& scenario, const ClosedLoopOptions& options, const LoopRun& run,
                          const LoopRun* without) {
  if (!options.pointing_path.empty()) {
    if (Status st = sim::write_pointing_csv(options.pointing_path, run.record, scenario.unit.gyro_count());
        !st)
      return st;
  }
  if (!options.summary_path.empty()) {
    std::string json = sim::summary_json(run.summary, run.record.fdi_events);
    if (without) {
      json = "{\n\"with_exclusion\": " + json +
             ",\n\"without_exclusion\": " + sim::summary_json(without->summary, true) + "}\n";
    }
    if (Status st = write_text_file(options.summary_path, json); !st) return st;
  }
  if (!options.plot_path.empty()) {
    std::vector<PlottedRun> runs = {{without ? "with exclusion" : "closed loop", &run.record}};
    if (without) runs.push_back({"without exclusion", &without->record});
    const std::string title = "tetra sim --closed-loop: " + scenario.name;
    return plot_pointing(options.plot_path, runs, run.summary.bound_deg, onsets_of(run.summary), title);
  }
  return ok_status();
}

}  // namespace

Status check_closed_loop_options(const sim::Scenario& scenario, const ClosedLoopOptions& options,
                                 bool over_dds) {
  if (!scenario.closed_loop) {
    return bad_input(scenario.name + ": --closed-loop needs a scenario file with a closed_loop: section");
  }
  if (!over_dds && options.real_time) return bad_input("--real-time needs --dds");
  if (over_dds && (options.compare_exclusion || options.no_exclusion || !options.calibration_path.empty() ||
                   !options.config_path.empty())) {
    return bad_input(
        "--compare-exclusion, --no-exclusion, --calibration and --config configure the pipeline in process; "
        "over --dds the service's own configuration applies");
  }
  return ok_status();
}

Status write_closed_loop_outputs(const sim::Scenario& scenario, const sim::ClosedLoopSimulator& simulator,
                                 const sim::ClosedLoopRecord& record, const ClosedLoopOptions& options,
                                 std::ostream& out) {
  LoopRun run{record, sim::summarize(record, simulator)};
  print_loop_summary(out, "", run.summary, run.record);
  return write_loop_outputs(scenario, options, run, nullptr);
}

Status run_closed_loop_to_files(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                                const ClosedLoopOptions& options, std::ostream& out) {
  if (Status st = check_closed_loop_options(scenario, options, false); !st) return st;
  Calibration calibration = scenario.unit;
  if (!options.calibration_path.empty()) {
    auto read = read_calibration(options.calibration_path);
    if (!read) return read.error();
    calibration = std::move(read.value());
  }
  fdi::PipelineConfig config;
  if (!options.config_path.empty()) {
    auto read = fdi::read_pipeline_config(options.config_path);
    if (!read) return read.error();
    config = read.value();
  }
  if (options.no_exclusion) config.exclusion_enabled = false;
  auto run = run_once(scenario, sim_options, calibration, config);
  if (!run) return run.error();
  print_loop_summary(out, options.compare_exclusion ? "with exclusion: " : "", run->summary, run->record);
  std::optional<LoopRun> without;
  if (options.compare_exclusion) {
    config.exclusion_enabled = false;
    auto second = run_once(scenario, sim_options, calibration, config);
    if (!second) return second.error();
    print_loop_summary(out, "without exclusion: ", second->summary, second->record);
    without = std::move(second.value());
  }
  return write_loop_outputs(scenario, options, *run, without ? &*without : nullptr);
}

}  // namespace tetra::report
