#pragma once
// The campaign runner (docs/campaign.md, "Running"): a campaign's runs in worker processes on this
// machine, handed out one run at a time, each run's row appended to DIR/runs.csv as it finishes. A run
// that fails (an error value, an exception), crashes its worker (a signal) or outlasts the per-run
// timeout is a row with outcome `error` and its message; a worker that dies or is killed is replaced.
// A folder remembers its spec (spec.sha256) and shard (shard.txt): a campaign continues in it only with
// the same spec and shard. POSIX processes and pipes only; the estimator comes from the caller (the
// fusion pipeline in process, or a DDS service the caller's factory starts).

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/campaign_report.hpp"

namespace tetra::campaign {

//! `--shard K/N`: this machine runs the indices i with i mod N = K − 1 (K from 1 to N).
struct Shard {
  std::size_t k = 1;
  std::size_t n = 1;
};
//! Parses "K/N" (1 ≤ K ≤ N ≤ kMaxCampaignRuns); the error says what is wrong with the text.
Result<Shard> parse_shard(const std::string& text);
//! "K/N".
std::string shard_text(const Shard& shard);
//! Whether run `index` belongs to `shard`.
inline bool in_shard(const Shard& shard, std::size_t index) {
  return index % shard.n == shard.k - 1;
}

//! [s] the default per-run timeout: generous against a 10-minute closed-loop run's ~0.05 s (or a DDS
//! run's few seconds); a run still going after it is a hung run.
inline constexpr double kDefaultRunTimeout_s = 600.0;

struct Progress {
  std::size_t total = 0;        //!< runs of this shard
  std::size_t done_before = 0;  //!< rows already in the folder when the campaign started
  std::size_t done_now = 0;     //!< rows written since
  std::size_t errors = 0;       //!< of them, error rows
  double elapsed_s = 0.0;       //!< [s] since the start
  bool final = false;           //!< the last report (every row in, or stopped)
  //! [runs/s] rows written since the start per second (0 before the first).
  double rate_per_s() const;
  //! [s] the time left at that rate (negative: unknown).
  double eta_s() const;
};

struct RunOptions {
  std::string out_dir;
  std::string spec_path;  //!< the spec file (copied to DIR/spec.yaml, hashed into DIR/spec.sha256)
  int jobs = 1;           //!< worker processes
  double run_timeout_s = kDefaultRunTimeout_s;  //!< [s] a run longer than this is killed: `error` row
  Shard shard;
  //! Called in each worker, once, before its first run: the estimators it runs with.
  std::function<sim::EstimatorFactory(const sim::CampaignSpec&)> estimators;
  //! Called in the campaign's process about once a second and at the end.
  std::function<void(const Progress&)> on_progress;
};

struct RunSummary {
  std::size_t total = 0;        //!< runs of this shard
  std::size_t done_before = 0;  //!< rows already in the folder
  std::size_t errors = 0;       //!< error rows now in runs.csv
  std::string runs_csv;         //!< DIR/runs.csv, complete and sorted by run
};

//! Prepares DIR (creates it, checks or writes spec.sha256, spec.yaml and shard.txt) and returns the
//! runs already in runs.csv (a torn last line dropped). A folder of another spec or shard is refused
//! (bad input naming the folder and the file that differs). Fills `summary` but runs nothing.
Result<std::vector<std::size_t>> prepare_folder(const sim::CampaignSpec& spec, const RunOptions& options,
                                                RunSummary& summary);

//! Runs what prepare_folder left to do, then sorts runs.csv by run. SIGINT/SIGTERM stop the workers
//! (an error saying how many rows are in and that the same command continues). Errors: the folder
//! cannot be written, a worker cannot be started, interrupted.
Result<RunSummary> run_campaign(const sim::CampaignSpec& spec, const RunOptions& options);

//! Lowercase hex SHA-256 of the spec as it runs: its YAML re-emitted (comments and layout do not
//! count), the contents of the scenario files it names and of the files they name (their units).
Result<std::string> campaign_spec_hash(const sim::CampaignSpec& spec, const std::string& spec_path);

//! `tetra campaign merge OUT SHARD_DIRS...`: checks that the folders hold one spec (spec.sha256), are
//! shards of one split (shard.txt), complete (every run of each shard, nothing else) and disjoint, and
//! together cover every run; then writes OUT/runs.csv sorted by run (the file a one-machine campaign
//! writes), spec.yaml, spec.sha256 and shard.txt (1/1). OUT must not be one of the shards.
Result<RunSummary> merge_shards(const std::string& out_dir, const std::vector<std::string>& shard_dirs);

//! The report options of a campaign folder (a merge's output, which has no spec object): the statistics
//! when runs.csv has dispersion columns, and the requirements of its spec.yaml — what
//! sim::report_options gives for the spec itself, so a merged report equals a one-machine one.
Result<sim::CampaignReportOptions> folder_report_options(const std::string& dir);

}  // namespace tetra::campaign
