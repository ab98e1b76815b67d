// tetra campaign SPEC.yaml — fault-injection campaigns, closed or open loop, with the fusion pipeline in
// process or in `tetra fusion` services over DDS (docs/campaign.md). The runs: tetra::campaign.
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>

#include <spdlog/fmt/fmt.h>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/campaign/dds_estimators.hpp"
#include "tetra/campaign/runner.hpp"
#include "tetra/report/campaign_report.hpp"
#include "tetra/sim/campaign.hpp"

namespace tetra::cli {

namespace {

constexpr const char* kCampaignName = "campaign";

std::string duration_text(double s) {
  if (s < 120.0) return fmt::format("{:.0f} s", s);
  if (s < 7200.0) return fmt::format("{:.1f} min", s / 60.0);
  return fmt::format("{:.1f} h", s / 3600.0);
}

//! "tetra campaign: 120/520 runs (1 error), 31.2 runs/s, 4 s elapsed, about 13 s left".
void print_campaign_progress(const campaign::Progress& p) {
  const std::size_t done = p.done_before + p.done_now;
  const double eta = p.eta_s();
  const bool all_in = done >= p.total;
  std::cerr << (isatty(2) ? "\r" : "") << "tetra campaign: " << done << "/" << p.total << " runs"
            << (p.errors ? fmt::format(" ({} error{})", p.errors, p.errors == 1 ? "" : "s") : std::string())
            << fmt::format(", {:.1f} runs/s, ", p.rate_per_s()) << duration_text(p.elapsed_s) << " elapsed, "
            << (p.final ? (all_in ? std::string("done") : std::string("stopped"))
                        : (eta < 0.0 ? std::string("time left unknown")
                                     : "about " + duration_text(eta) + " left"))
            << (isatty(2) && !p.final ? "   " : "\n") << std::flush;
}

//! The command line's values that are not campaign::RunOptions.
struct CampaignArgs {
  std::string spec_path;
  bool no_report = false;
  std::string shard_text;
  long long rerun = -1;  //!< --run K: that run again, alone
  std::string events_path;
  int domain = 0;
  CLI::Option* domain_opt = nullptr;
};

void add_campaign_options(CLI::App& app, CampaignArgs& a, campaign::RunOptions& options) {
  app.add_option("SPEC", a.spec_path, "campaign spec YAML")->required();
  app.add_option("--out,-o", options.out_dir,
                 "output folder: runs.csv, report.md, plots, spec.yaml, spec.sha256, shard.txt (target "
                 "dds: dds/, the services' files while they run); required unless --run");
  app.add_option("--jobs,-j", options.jobs, "worker processes (default: the number of cores; at most 1024)")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  app.add_option("--run-timeout", options.run_timeout_s,
                 "[s] a run without its row after this long is killed and is an error row")
      ->check(CLI::Range(0.001, 1e7))
      ->capture_default_str();
  app.add_option("--shard", a.shard_text,
                 "K/N: run only the runs i with i mod N = K-1 (K from 1 to N), e.g. one Slurm array task; "
                 "no report (tetra campaign merge writes it)");
  app.add_flag("--no-report", a.no_report, "only the runs (no report, no plots)");
  app.add_option(
         "--run", a.rerun,
         "K: run K of the campaign (runs.csv's `run`) again, alone and in process, with the same draws; "
         "its row on standard output (header and row), nothing else written but --events")
      ->check(CLI::Range(0LL, 999999LL));
  app.add_option("--events", a.events_path,
                 "with --run: the run's FDI events as JSON lines (each decision with its ledger rows)");
  a.domain_opt = app.add_option("--domain", a.domain,
                                "DDS domain of the services (target dds; overrides the spec's domain:)")
                     ->check(CLI::Range(0, 232));
}

//! The spec as the command line amends it (--domain), and the run options it implies (--shard, DDS).
Result<sim::CampaignSpec> campaign_setup(const CampaignArgs& a, campaign::RunOptions& options) {
  if (!a.shard_text.empty()) {
    auto shard = campaign::parse_shard(a.shard_text);
    if (!shard) return shard.error();
    options.shard = *shard;
  }
  auto spec = sim::read_campaign_spec(a.spec_path);
  if (!spec) return spec.error();
  if (a.domain_opt->count() != 0) {
    if (spec->target != sim::CampaignTarget::kDds)
      return bad_input("--domain applies to a campaign with target: dds only");
    spec->dds_domain = a.domain;
  }
  if (spec->target == sim::CampaignTarget::kDds) {
    const std::string dds_dir = (std::filesystem::path(options.out_dir) / "dds").string();
    options.estimators = [dds_dir](const sim::CampaignSpec& s) {
      return campaign::dds_campaign_estimators(s, dds_dir);
    };
  }
  options.spec_path = a.spec_path;
  options.on_progress = print_campaign_progress;
  return spec;
}

//! Prepares the folder (and the services' folder over DDS) and says what is about to run.
Status prepare(const sim::CampaignSpec& spec, const campaign::RunOptions& options) {
  campaign::RunSummary summary;
  auto pending = campaign::prepare_folder(spec, options, summary);
  if (!pending) return pending.error();
  const bool over_dds = spec.target == sim::CampaignTarget::kDds;
  if (over_dds) {
    const std::string dds_dir = (std::filesystem::path(options.out_dir) / "dds").string();
    std::error_code ec;
    std::filesystem::create_directories(dds_dir, ec);
    if (ec) return failure(dds_dir + ": cannot create the folder");
  }
  std::cerr << "tetra campaign: " << summary.total << " runs"
            << (options.shard.n > 1 ? " of shard " + campaign::shard_text(options.shard) : std::string())
            << " (" << (spec.loop == sim::CampaignLoop::kClosed ? "closed" : "open") << " loop, "
            << (over_dds ? "fusion services over DDS, domain " + std::to_string(spec.dds_domain)
                         : std::string("pipeline in process"))
            << "), " << summary.done_before << " already done, " << options.jobs << " jobs\n";
  return ok_status();
}

//! The in-process pipeline of a run, its events kept for --events.
class KeepingEstimator final : public sim::Estimator {
 public:
  KeepingEstimator(std::unique_ptr<sim::Estimator> inner, std::vector<fdi::FdiEvent>& kept)
      : inner_(std::move(inner)), kept_(kept) {}
  Result<sim::EstimatorOutput> estimate(const sim::SimEpoch& epoch) override {
    auto out = inner_->estimate(epoch);
    if (out) kept_.insert(kept_.end(), out->events.begin(), out->events.end());
    return out;
  }
  Status finish(std::vector<fdi::FdiEvent>& events) override {
    const std::size_t before = events.size();
    Status st = inner_->finish(events);
    kept_.insert(kept_.end(), events.begin() + static_cast<std::ptrdiff_t>(before), events.end());
    return st;
  }

 private:
  std::unique_ptr<sim::Estimator> inner_;
  std::vector<fdi::FdiEvent>& kept_;
};

//! --run K: the run again with the pipeline in process; its row on stdout, its events to `events_path`.
int rerun_one(const sim::CampaignSpec& spec, std::size_t index, const std::string& events_path) {
  auto total = sim::campaign_run_count(spec);
  if (!total) return report(kCampaignName, total.error());
  if (index >= *total)
    return report(kCampaignName, bad_input(fmt::format("--run {}: the campaign has runs 0 to {}", index,
                                                       *total == 0 ? 0 : *total - 1)));
  std::vector<fdi::FdiEvent> events;
  const sim::EstimatorFactory inner = sim::in_process_estimators(spec);
  const sim::EstimatorFactory keeping = [&](const sim::Scenario& scenario, const sim::CampaignCase& c,
                                            const Quaternion& q) -> Result<std::unique_ptr<sim::Estimator>> {
    auto made = inner(scenario, c, q);
    if (!made) return made.error();
    return std::unique_ptr<sim::Estimator>(std::make_unique<KeepingEstimator>(std::move(*made), events));
  };
  const sim::CampaignRow row = sim::campaign_run_row(spec, index, keeping);
  std::cout << sim::campaign_csv_header(spec) << '\n' << sim::campaign_csv_row(row) << '\n';
  if (!events_path.empty()) {
    std::string text;
    for (const fdi::FdiEvent& e : events) text += fdi::to_json(e, spec.max_gyro_count()) + "\n";
    if (Status st = write_text_file(events_path, text); !st) return report(kCampaignName, st.error());
    std::cerr << "tetra campaign: run " << index << ": " << events.size() << " events -> " << events_path
              << '\n';
  }
  return row.error.empty() ? kExitOk : kExitFailure;
}

}  // namespace

int cmd_campaign(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "merge") == 0) return cmd_campaign_merge(argc - 1, argv + 1);
  CLI::App app{
      "Fault-injection campaign: scenarios x fault kinds x gyros x onsets x sizes x seeds, in parallel "
      "processes handed one run at a time; one row per run (a run that fails, crashes its worker or times "
      "out is an error row) and a report with plots (docs/campaign.md). The spec selects closed loop "
      "(`loop: closed`, the default: the controller steers with the estimate) or open loop (`loop: open`: "
      "the scenarios' own motion), and the fusion pipeline in process (`target: in_process`, the default) "
      "or one `tetra fusion` service per run over DDS in lockstep (`target: dds`, `domain: N`). "
      "Interrupted campaigns continue where they stopped. `--shard K/N` runs a part for a cluster; "
      "`tetra campaign merge OUT SHARD_DIRS...` joins the parts.",
      kCampaignName};
  CampaignArgs args;
  campaign::RunOptions options;
  options.jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  add_campaign_options(app, args, options);
  if (auto status = parse(app, argc, argv)) return *status;

  auto spec = campaign_setup(args, options);
  if (!spec) return report(kCampaignName, spec.error());
  if (args.rerun >= 0) return rerun_one(*spec, static_cast<std::size_t>(args.rerun), args.events_path);
  if (!args.events_path.empty()) return report(kCampaignName, bad_input("--events needs --run K"));
  if (options.out_dir.empty()) return report(kCampaignName, bad_input("--out is required (unless --run K)"));
  if (Status st = prepare(*spec, options); !st) return report(kCampaignName, st.error());
  auto done = campaign::run_campaign(*spec, options);
  if (!done) return report(kCampaignName, done.error());
  if (done->errors > 0)
    std::cerr << "tetra campaign: " << done->errors << " of " << done->total
              << " runs ended in an error (rows with outcome error in " << done->runs_csv << ")\n";
  if (args.no_report || options.shard.n > 1) return kExitOk;
  if (Status st = report::write_campaign_report(done->runs_csv, options.out_dir, sim::report_options(*spec));
      !st)
    return report(kCampaignName, st.error());
  std::cerr << "tetra campaign: report -> "
            << (std::filesystem::path(options.out_dir) / sim::kReportMarkdown).string() << '\n';
  return kExitOk;
}

}  // namespace tetra::cli
