// tetra campaign merge OUT SHARD_DIRS... — the shards of a campaign (`--shard K/N`) into one folder with
// the runs.csv and report a one-machine campaign writes (docs/campaign.md, "Shards and Slurm").
#include <iostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/campaign/runner.hpp"
#include "tetra/report/campaign_report.hpp"

namespace tetra::cli {

int cmd_campaign_merge(int argc, char** argv) {
  constexpr const char* kName = "campaign merge";
  CLI::App app{
      "Merges the shards of a campaign (tetra campaign SPEC --shard K/N --out DIR_K): checks that they hold "
      "one spec (spec.sha256), are complete and disjoint and cover every run, then writes OUT/runs.csv "
      "sorted by run and the report, as one machine running the whole campaign writes them.",
      "campaign merge"};
  std::string out_dir;
  std::vector<std::string> shard_dirs;
  bool no_report = false;
  app.add_option("OUT", out_dir, "output folder")->required();
  app.add_option("SHARD_DIRS", shard_dirs, "the shards' --out folders")->required();
  app.add_flag("--no-report", no_report, "only runs.csv (no report, no plots)");
  if (auto status = parse(app, argc, argv)) return *status;
  auto merged = campaign::merge_shards(out_dir, shard_dirs);
  if (!merged) return report(kName, merged.error());
  std::cerr << "tetra campaign merge: " << merged->total << " runs from " << shard_dirs.size() << " shards"
            << (merged->errors ? " (" + std::to_string(merged->errors) + " error rows)" : std::string())
            << " -> " << merged->runs_csv << '\n';
  if (no_report) return kExitOk;
  auto options = campaign::folder_report_options(out_dir);
  if (!options) return report(kName, options.error());
  if (Status st = report::write_campaign_report(merged->runs_csv, out_dir, *options); !st)
    return report(kName, st.error());
  std::cerr << "tetra campaign merge: report -> " << out_dir << "/report.md\n";
  return kExitOk;
}

}  // namespace tetra::cli
