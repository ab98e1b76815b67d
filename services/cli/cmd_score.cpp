// tetra score — attitude error of an estimate against the simulator's truth: per axis and total, NEES,
// fractions within 1/2/3σ, integrated angle about an axis, and the error against its ±3σ envelope as a plot.
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/report/score_report.hpp"

namespace tetra::cli {

int cmd_score(int argc, char** argv) {
  CLI::App app(
      "Score an attitude estimate (tetra replay --attitude) against the truth (tetra sim --truth): error per "
      "body axis and total, NEES and the fractions of epochs within 1/2/3 sigma (per-axis sigma columns when "
      "present, else sigma_deg), the integrated angle about an axis, and the error against its +-3 sigma "
      "envelope as a plot. Rows are matched by time: a truth row within --time-tolerance, else the truth "
      "interpolated between its rows; rows outside the truth's time span are counted, not scored.",
      "score");
  report::ScoreReportOptions o;
  o.names = {{"attitude_path", "ATT.csv"},
             {"truth_path", "TRUTH.csv"},
             {"plot_path", "--plot"},
             {"json_path", "--json"}};
  app.add_option("ATT.csv", o.attitude_path,
                 "attitude: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,...")
      ->required();
  app.add_option("TRUTH.csv", o.truth_path, "truth: time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps")->required();
  app.add_option("--plot", o.plot_path,
                 "write the error per axis against +-3 sigma as a PNG (needs gnuplot)");
  app.add_option("--json", o.json_path, "write the figures as JSON");
  app.add_option("--axis", o.axis,
                 "axis of the integrated angle: x, y, z or a body vector a,b,c (default y, the seed's turn)");
  app.add_option("--time-tolerance", o.time_tolerance_s,
                 "[s] an attitude row and a truth row this close in time are the same epoch (default 1e-6)");
  if (auto status = parse(app, argc, argv)) return *status;
  if (auto score = report::write_score_report(o, std::cout); !score) {
    return report("score", score.error(),
                  {{report::kSubjectAxis, "--axis '{value}': {message}"},
                   {"axis_B", "--axis: {message}"},
                   {"time_tolerance_s", "--time-tolerance: {message}"}});
  }
  return kExitOk;
}

}  // namespace tetra::cli
