// tetra campaign SPEC.yaml — fault-injection campaigns, closed or open loop, with the fusion pipeline in
// process or in `tetra fusion` services over DDS (docs/campaign.md).
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/fmt/fmt.h>

#include "campaign_dds.hpp"
#include "campaign_report.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/sim/campaign.hpp"

namespace tetra::cli {

namespace {

constexpr const char* kCampaignName = "campaign";

// SIGINT/SIGTERM: the workers are told to stop (each worker's `tetra fusion` services follow it, see
// spawn_self), the rows already finished stay in runs.csv, and the same command continues the campaign.
constexpr std::size_t kMaxWorkers = 1024;
volatile std::sig_atomic_t g_stop_signal = 0;
pid_t g_worker_pids[kMaxWorkers] = {};
volatile std::sig_atomic_t g_worker_count = 0;

extern "C" void campaign_on_signal(int sig) {
  g_stop_signal = sig;
  for (std::sig_atomic_t i = 0; i < g_worker_count; ++i) ::kill(g_worker_pids[i], SIGTERM);
}

//! Installs (or, with `install` false, removes) the handler for SIGINT and SIGTERM.
void handle_stop_signals(bool install) {
  struct sigaction action {};
  action.sa_handler = install ? campaign_on_signal : SIG_DFL;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

//! Run ids already in `runs.csv` (a torn last line, from an interrupted run, is dropped and redone).
Result<std::set<std::size_t>> done_runs(const std::string& path, const std::string& header) {
  std::set<std::size_t> done;
  std::ifstream in(path);
  if (!in) return done;
  std::string line;
  if (!std::getline(in, line)) return done;
  if (line != header)
    return bad_input(path + ":1: not the header of this campaign (another version, or other dispersions)");
  std::string kept = line + "\n";
  while (std::getline(in, line)) {
    auto row = sim::parse_campaign_row(line, header);
    if (!row) continue;
    done.insert(row->run);
    kept += line + "\n";
  }
  in.close();
  std::ofstream rewrite(path, std::ios::trunc);  // without the torn line
  rewrite << kept;
  if (!rewrite) return failure(path + ": cannot rewrite");
  return done;
}

//! A worker process: runs its share of the cases, one row per line on `fd` (each write below
//! PIPE_BUF, so lines of several workers never interleave).
[[noreturn]] void worker(const sim::CampaignSpec& spec, const std::vector<std::size_t>& cases, int fd,
                         const std::string& out_dir) {
  const sim::EstimatorFactory make =
      spec.target == sim::CampaignTarget::kDds
          ? dds_campaign_estimators(spec, (std::filesystem::path(out_dir) / "dds").string())
          : sim::in_process_estimators(spec);
  for (std::size_t index : cases) {
    auto row = sim::run_campaign_case(spec, sim::campaign_case(spec, index), make);
    const std::string line = row ? sim::campaign_csv_row(*row) + "\n" : "error " + row.error().message + "\n";
    if (::write(fd, line.data(), line.size()) != static_cast<ssize_t>(line.size())) ::_exit(1);
  }
  ::_exit(0);
}

std::string duration_text(double s) {
  if (s < 120.0) return fmt::format("{:.0f} s", s);
  if (s < 7200.0) return fmt::format("{:.1f} min", s / 60.0);
  return fmt::format("{:.1f} h", s / 3600.0);
}

struct Progress {
  std::size_t total = 0;
  std::size_t done_before = 0;
  std::size_t done_now = 0;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  void print(bool final) const {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::size_t left = total - done_before - done_now;
    std::string eta =
        done_now ? duration_text(elapsed / static_cast<double>(done_now) * static_cast<double>(left)) : "?";
    std::cerr << (isatty(2) ? "\r" : "") << "tetra campaign: " << done_before + done_now << "/" << total
              << " runs, " << duration_text(elapsed) << " elapsed, "
              << (final ? "done" : "about " + eta + " left") << (isatty(2) && !final ? "   " : "\n")
              << std::flush;
  }
};

Status run_pending(const sim::CampaignSpec& spec, const std::vector<std::size_t>& pending, int jobs,
                   const std::string& out_dir, Progress& progress) {
  const std::string runs_path = (std::filesystem::path(out_dir) / "runs.csv").string();
  int fds[2];
  if (::pipe(fds) != 0) return failure("cannot create a pipe");
  std::vector<pid_t> pids;
  const auto n_jobs = static_cast<std::size_t>(
      std::max(1, std::min<int>({jobs, static_cast<int>(pending.size()), static_cast<int>(kMaxWorkers)})));
  const pid_t parent = ::getpid();
  for (std::size_t w = 0; w < n_jobs && g_stop_signal == 0; ++w) {
    std::vector<std::size_t> share;
    for (std::size_t i = w; i < pending.size(); i += n_jobs) share.push_back(pending[i]);
    std::cout.flush();
    const pid_t pid = ::fork();
    if (pid < 0) return failure("cannot fork a worker");
    if (pid == 0) {
      handle_stop_signals(false);
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);  // a campaign killed outright takes its workers with it
      if (::getppid() != parent) ::_exit(1);
      ::close(fds[0]);
      worker(spec, share, fds[1], out_dir);
    }
    pids.push_back(pid);
    g_worker_pids[w] = pid;
    g_worker_count = static_cast<std::sig_atomic_t>(w + 1);
    if (g_stop_signal != 0) ::kill(pid, SIGTERM);  // the signal came between fork and the line above
  }
  ::close(fds[1]);
  std::FILE* in = ::fdopen(fds[0], "r");
  std::ofstream out(runs_path, std::ios::app);
  std::string first_error;
  auto next_print = std::chrono::steady_clock::now();
  char* buffer = nullptr;
  std::size_t capacity = 0;
  while (::getline(&buffer, &capacity, in) > 0) {
    std::string line(buffer);
    if (line.rfind("error ", 0) == 0) {
      if (first_error.empty()) first_error = line.substr(6, line.size() - 7);
      continue;
    }
    out << line << std::flush;  // one complete row at a time: an interruption loses no finished run
    ++progress.done_now;
    if (std::chrono::steady_clock::now() >= next_print) {
      progress.print(false);
      next_print += std::chrono::seconds(1);
    }
  }
  std::free(buffer);
  std::fclose(in);
  bool workers_ok = true;
  for (pid_t pid : pids) {
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    workers_ok = workers_ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  }
  g_worker_count = 0;
  progress.print(true);
  if (g_stop_signal != 0) {
    return failure(std::string("interrupted by ") + (g_stop_signal == SIGINT ? "SIGINT" : "SIGTERM") +
                   ": workers stopped, " + std::to_string(progress.done_before + progress.done_now) + " of " +
                   std::to_string(progress.total) + " runs in " + runs_path +
                   "; the same command continues the campaign");
  }
  if (!first_error.empty()) return failure("a run failed: " + first_error);
  if (!workers_ok || !out) return failure(runs_path + ": a worker failed or the file could not be written");
  return ok_status();
}

}  // namespace

int cmd_campaign(int argc, char** argv) {
  CLI::App app{
      "Fault-injection campaign: scenarios x fault kinds x gyros x onsets x sizes x seeds, in parallel "
      "processes; one row per run and a report with plots (docs/campaign.md). The spec selects closed loop "
      "(`loop: closed`, the default: the controller steers with the estimate) or open loop (`loop: open`: "
      "the scenarios' own motion), and the fusion pipeline in process (`target: in_process`, the default) "
      "or one `tetra fusion` service per run over DDS in lockstep (`target: dds`, `domain: N`). "
      "Interrupted campaigns continue where they stopped.",
      kCampaignName};
  std::string spec_path;
  std::string out_dir;
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  bool no_report = false;
  app.add_option("SPEC", spec_path, "campaign spec YAML")->required();
  app.add_option(
         "--out,-o", out_dir,
         "output folder: runs.csv, report.md, plots (target dds: dds/, the services' files while they run)")
      ->required();
  app.add_option("--jobs,-j", jobs, "worker processes (default: the number of cores)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--no-report", no_report, "only the runs (no report, no plots)");
  int domain = 0;
  CLI::Option* domain_opt =
      app.add_option("--domain", domain,
                     "DDS domain of the services (target dds; overrides the spec's domain:)")
          ->check(CLI::Range(0, 232));
  if (auto status = parse(app, argc, argv)) return *status;

  auto spec = sim::read_campaign_spec(spec_path);
  if (!spec) return report(kCampaignName, spec.error());
  if (domain_opt->count() != 0) {
    if (spec->target != sim::CampaignTarget::kDds)
      return report(kCampaignName, bad_input("--domain applies to a campaign with target: dds only"));
    spec->dds_domain = domain;
  }
  std::error_code ec;
  const bool over_dds = spec->target == sim::CampaignTarget::kDds;
  std::filesystem::create_directories(
      over_dds ? std::filesystem::path(out_dir) / "dds" : std::filesystem::path(out_dir), ec);
  if (ec) return report(kCampaignName, failure(out_dir + ": cannot create the folder"));
  const std::string runs_path = (std::filesystem::path(out_dir) / "runs.csv").string();
  // runs.csv is appended to in place (an interrupted campaign resumes): a FIFO or a write-protected
  // file is refused as any output is.
  if (Status st = check_output_path(runs_path, "campaign output"); !st)
    return report(kCampaignName, st.error());
  auto done = done_runs(runs_path, sim::campaign_csv_header(*spec));
  if (!done) return report(kCampaignName, done.error());
  if (done->empty()) {
    std::ofstream header(runs_path, std::ios::trunc);
    header << sim::campaign_csv_header(*spec) << '\n';
    if (!header) return report(kCampaignName, failure(runs_path + ": cannot write"));
  }
  // Bounded (read_campaign_spec): at most kMaxCampaignRuns indices; the cases are made one at a time.
  const auto total = sim::campaign_run_count(*spec);
  if (!total) return report(kCampaignName, total.error());
  std::vector<std::size_t> pending;
  for (std::size_t index = 0; index < *total; ++index) {
    if (done->count(index) == 0) pending.push_back(index);
  }
  std::cerr << "tetra campaign: " << *total << " runs ("
            << (spec->loop == sim::CampaignLoop::kClosed ? "closed" : "open") << " loop, "
            << (spec->target == sim::CampaignTarget::kDds
                    ? "fusion services over DDS, domain " + std::to_string(spec->dds_domain)
                    : std::string("pipeline in process"))
            << "), " << *total - pending.size() << " already done, " << jobs << " jobs\n";
  Progress progress{*total, *total - pending.size()};
  if (!pending.empty()) {
    handle_stop_signals(true);
    Status st = run_pending(*spec, pending, jobs, out_dir, progress);
    handle_stop_signals(false);
    if (!st) return report(kCampaignName, st.error());
  }
  if (no_report) return kExitOk;
  if (Status st = write_campaign_report(*spec, out_dir); !st) return report(kCampaignName, st.error());
  std::cerr << "tetra campaign: report -> " << (std::filesystem::path(out_dir) / "report.md").string()
            << '\n';
  return kExitOk;
}

}  // namespace tetra::cli
