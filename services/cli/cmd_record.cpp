// tetra record -o LOG.csv — the gyro and reference streams of one unit on DDS, written as a
// replayable gyro log (tetra/dds_tools/record.hpp). Stops on SIGINT/SIGTERM, after --duration, or with
// --until-idle when the gyro writers are gone.

#include <iostream>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/dds_tools/record.hpp"

namespace tetra::cli {

namespace {

void add_record_options(CLI::App& app, dds_tools::RecordOptions& o) {
  app.add_option("-o,--out", o.out_path, "gyro log to write (CSV, or HDF5 when named .h5)")->required();
  app.add_option("--unit", o.unit, "the unit to record (default: the first one seen)")
      ->check(unit_name_check());
  app.add_option("--config", o.config_path,
                 "take unit, gyro count and assembly settings from a fusion config");
  app.add_option("--gyros", o.gyros, "number of gyros N (columns g1..gN)")
      ->check(CLI::Range(1, dds::kMaxGyrosOnWire));
  app.add_option("--rate", o.rate_hz, "[Hz] nominal sample rate")->check(CLI::Range(0.001, 100000.0));
  app.add_option("--tolerance", o.tolerance_s,
                 "[s] stamps this close form one epoch (default: a quarter period)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-latency", o.max_latency_s, "[s] longest wait for an epoch's missing samples")
      ->check(CLI::PositiveNumber);
  app.add_option("--attitude", o.attitude_path,
                 "also write the service's Attitude (CSV, docs/interfaces.md §2.4)");
  app.add_option("--events", o.events_path,
                 "also write the service's FdiEvents (JSON lines, docs/interfaces.md §2.5)");
  app.add_option(
      "--commands", o.commands_path,
      "also write the operator commands the service acknowledged (JSON lines, for replay --commands)");
  app.add_option("--duration", o.duration_s, "[s] stop after this long")->check(CLI::PositiveNumber);
  app.add_flag("--until-idle", o.until_idle, "stop when the gyro writers have come and gone");
  add_domain_option(app, o.domain);
}

}  // namespace

int cmd_record(int argc, char** argv) {
  dds::ShutdownSignal shutdown;
  CLI::App app{"Record a unit's gyro and reference streams on DDS as a replayable gyro log.", "record"};
  dds_tools::RecordOptions o;
  o.names = {{"command", "tetra record"},     {"config_path", "--config"}, {"out_path", "--out"},
             {"attitude_path", "--attitude"}, {"events_path", "--events"}, {"commands_path", "--commands"}};
  add_record_options(app, o);
  if (auto exit = parse(app, argc, argv)) return *exit;
  auto recorded = dds_tools::record_unit(o, shutdown, std::cerr);
  if (!recorded) return report("record", recorded.error());
  const auto& c = recorded->counters;
  std::cerr << "tetra record: " << recorded->epochs << " epochs of unit "
            << (recorded->unit.empty() ? "(none seen)" : recorded->unit) << " written to " << o.out_path
            << " (late " << c.samples_late << ", duplicate " << c.samples_duplicate << ", out of order "
            << c.samples_out_of_order << ", gap " << c.samples_gap << ", time outlier " << c.time_outlier
            << ", sequence jump " << c.seq_discontinuity << ", restarts " << c.sensor_restarts << ")\n";
  if (recorded->gyro_samples_lost > 0 || recorded->attitudes_lost > 0) {
    std::cerr << "tetra record: " << recorded->gyro_samples_lost << " gyro samples and "
              << recorded->attitudes_lost
              << " attitudes lost (dropped by a writer before this recorder had them, or said written for an "
                 "epoch and never in): the files lack them\n";
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace tetra::cli
