#include "sim_dds.hpp"

#include <iostream>

#include "cli_common.hpp"
#include "dds_common.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/dds/shutdown.hpp"

namespace tetra::cli {

void add_sim_dds_options(CLI::App& app, SimDdsCliOptions& options) {
  app.add_flag("--dds", options.enabled,
               "publish on DDS (GyroSample, AttitudeReference) instead of writing files, "
               "and score the Attitude received against the truth");
  app.add_option("--speed", options.speed,
                 "--dds: 1 = real time, X = X times faster, 0 = as fast as possible (at most 1e6)")
      ->check(number_in(0.0, 1.0e6))
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {  // a slower clock than 1/1000 would overflow the pacing
            const auto v = parse_decimal(text);
            return v && *v > 0.0 && *v < 1e-3
                       ? "'" + text + "' must be 0 (as fast as possible) or at least 0.001"
                       : std::string();
          },
          "", "0 or at least 0.001"));
  app.add_option("--dds-unit", options.unit, "--dds: the unit's key on the wire (default: the unit's name)")
      ->check(unit_name_check());
  app.add_option("--wait-readers", options.wait_readers, "--dds: gyro readers to wait for before publishing")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wait-timeout", options.wait_timeout_s,
                 "[s] --dds: how long to wait for them (at most a day)")
      ->check(number_in(0.0, 86400.0, true));
  add_domain_option(app, options.domain);
}

int sim_dds_main(sim::Simulator& simulator, const SimDdsCliOptions& options) {
  dds::ShutdownSignal shutdown;
  const auto progress = [&](const SimDdsScore& s) {
    if (options.quiet) return;
    std::cerr << "tetra sim: " << s.epochs_published << " epochs published, " << s.attitudes_scored
              << " attitudes scored";
    if (!s.series.empty()) {
      std::cerr << "; t = " << fixed(s.series.back().time_s, 2) << " s error now "
                << fixed(s.series.back().error_deg, 5) << " deg, worst " << fixed(s.worst_deg, 5)
                << " deg, mode " << s.series.back().mode << " gyros " << s.series.back().gyros;
    }
    std::cerr << '\n';
  };
  auto score = run_sim_dds(simulator, options, &shutdown, progress);
  if (!score) return report("sim", score.error());
  std::cout << "epochs published: " << score->epochs_published << " in " << fixed(score->wall_s, 2) << " s\n"
            << "attitudes scored: " << score->attitudes_scored << '\n';
  if (score->missing > 0) {
    std::cout << "epochs without an attitude: " << score->missing
              << " (the first at t = " << fixed(score->first_missing_s, 3) << " s)\n";
  }
  if (score->series.empty()) {
    std::cout << "attitude error: no Attitude received for this unit (is `tetra fusion` running?)\n";
    if (!shutdown.requested() && options.wait_readers > 0 && score->epochs_published > 0) {
      // Loud, not silent: a service for another unit (or none) ignored every sample.
      const std::string unit = options.unit.empty() ? simulator.scenario().unit.unit : options.unit;
      return report("sim", failure("--dds: no service accepted the samples of unit '" + unit +
                                   "' (no Attitude came back; check the service's unit against --dds-unit)"));
    }
  } else {
    std::cout << "attitude error now: " << fixed(score->series.back().error_deg, 6) << " deg (mode "
              << score->series.back().mode << ", gyros " << score->series.back().gyros << ")\n"
              << "attitude error worst: " << fixed(score->worst_deg, 6)
              << " deg at t = " << fixed(score->worst_time_s, 3) << " s\n";
  }
  return shutdown.requested() ? kExitFailure : kExitOk;
}

}  // namespace tetra::cli
