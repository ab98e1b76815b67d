// tetra play LOG — a recorded gyro log (CSV, HDF5 or TDMS) back on DDS as the unit would publish it, paced
// by its own times (docs/dds.md, "Playing a log"). The partner of `tetra record`.
#include <iostream>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/player/log_player.hpp"

namespace tetra::cli {

namespace {

struct PlayCli {
  std::string log_path;
  std::string speed = "1";
  double start_s = 0.0;
  double end_s = 0.0;
  bool quiet = false;
  player::PlayOptions options;
};

void add_play_options(CLI::App& app, PlayCli& o) {
  app.add_option("LOG", o.log_path, "gyro log in volts (CSV, HDF5 when named .h5, TDMS when named .tdms)")
      ->required();
  app.add_option("--speed", o.speed,
                 "1 = the log's pace, X = X times faster (0.001 to 1e6), max = as fast as the service keeps "
                 "up (lockstep: each epoch waits for the service's Attitude of it)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            if (text == "max") return {};
            const auto v = parse_decimal(text);
            return v && *v >= 1e-3 && *v <= 1e6 ? std::string()
                                                : "'" + text + "' must be max or from 0.001 to 1e6";
          },
          "max|X", "speed"));
  app.add_flag("--loop", o.options.loop, "start again at the end, times continuing (until Ctrl-C)");
  app.add_option("--start", o.start_s, "[s] first log time to play (inclusive)")->check(number_in(-9e9, 9e9));
  app.add_option("--end", o.end_s, "[s] last log time to play (inclusive)")->check(number_in(-9e9, 9e9));
  app.add_option("--unit", o.options.unit,
                 "the unit's key on the wire (default: the log's '# unit=' comment, else tetra-1)")
      ->check(unit_name_check());
  app.add_option("--wait-readers", o.options.wait_readers, "GyroSample readers to wait for before publishing")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wait-timeout", o.options.wait_timeout_s, "[s] how long to wait for them (at most a day)")
      ->check(number_in(0.0, 86400.0, true));
  app.add_flag("-q,--quiet", o.quiet, "no progress lines on stderr");
  add_domain_option(app, o.options.domain);
}

void print_play_report(const player::PlayReport& r, bool lockstep) {
  std::cout << "unit: " << r.unit << '\n'
            << "epochs published: " << r.epochs << " (" << r.samples << " gyro samples, " << r.references
            << " references) in " << fixed(r.wall_s, 2) << " s, " << r.passes
            << (r.passes == 1 ? " pass" : " passes") << '\n'
            << "log times: " << fixed(r.first_time_s, 3) << " to " << fixed(r.last_time_s, 3) << " s\n"
            << "attitudes received: " << r.attitudes << '\n';
  if (lockstep) {
    std::cout << "lockstep epochs without an attitude in time: " << r.lockstep_missing << '\n';
  } else {
    std::cout << "worst lateness of a write behind the log's pace: " << fixed(r.worst_lag_ms, 3) << " ms\n";
  }
}

}  // namespace

int cmd_play(int argc, char** argv) {
  CLI::App app{
      "Play a gyro log on DDS (GyroSample, and AttitudeReference when the log has one) at its recorded pace, "
      "faster, or in lockstep with the service: the partner of tetra record (docs/dds.md)."};
  PlayCli o;
  add_play_options(app, o);
  if (auto code = parse(app, argc, argv)) return *code;
  o.options.speed = o.speed == "max" ? 0.0 : *parse_decimal(o.speed);
  if (app.count("--start") > 0) o.options.start_s = o.start_s;
  if (app.count("--end") > 0) o.options.end_s = o.end_s;
  if (o.options.start_s && o.options.end_s && *o.options.end_s < *o.options.start_s) {
    return report("play",
                  bad_input("--end " + fixed(o.end_s, 3) + " is before --start " + fixed(o.start_s, 3)));
  }
  dds::ShutdownSignal shutdown;
  const auto progress = [&](const player::PlayReport& r) {
    if (o.quiet) return;
    std::cerr << "tetra play: " << r.epochs << " epochs, log time " << fixed(r.last_time_s, 2) << " s, "
              << r.attitudes << " attitudes received\n";
  };
  auto result = player::play_log(o.log_path, o.options, &shutdown, progress);
  if (!result) return report("play", result.error());
  print_play_report(*result, o.options.speed <= 0.0);
  if (result->attitudes == 0 && o.options.wait_readers > 0 && !shutdown.requested()) {
    std::cout << "no Attitude came back for unit '" << result->unit
              << "' (is `tetra fusion` running for this unit on this domain?)\n";
  }
  return shutdown.requested() ? kExitFailure : kExitOk;
}

}  // namespace tetra::cli
