// The campaign's worker processes: one run at a time handed to an idle worker over its pipe, its row
// read back over another; crashed, killed and timed-out workers replaced, their run an error row.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <iostream>
#include <optional>

#include "folder.hpp"
#include "tetra/campaign/runner.hpp"

namespace tetra::campaign {

namespace {

using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void campaign_runner_on_signal(int sig) {
  g_stop_signal = sig;
}

//! While it lives: SIGINT and SIGTERM ask the campaign to stop (poll returns early: no SA_RESTART);
//! SIGPIPE is ignored (a write to a worker that just died is an error value, not the end).
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    struct sigaction action {};
    action.sa_handler = campaign_runner_on_signal;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, &old_int_);
    ::sigaction(SIGTERM, &action, &old_term_);
    action.sa_handler = SIG_IGN;
    ::sigaction(SIGPIPE, &action, &old_pipe_);
  }
  ~StopSignals() {
    ::sigaction(SIGINT, &old_int_, nullptr);
    ::sigaction(SIGTERM, &old_term_, nullptr);
    ::sigaction(SIGPIPE, &old_pipe_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
  struct sigaction old_pipe_ {};
};

struct Worker {
  pid_t pid = -1;
  int task_fd = -1;    //!< the campaign writes run indices, one a line
  int result_fd = -1;  //!< the worker writes rows, one a line
  std::string buffer;  //!< a row read in part
  std::optional<std::size_t> run;
  Clock::time_point deadline;
};

bool write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

//! The row of one run: an error value or an exception is an error row with its message.
std::string run_row(const sim::CampaignSpec& spec, std::size_t index, const sim::EstimatorFactory& make) {
  return sim::campaign_csv_row(sim::campaign_run_row(spec, index, make));
}

[[noreturn]] void worker_main(const sim::CampaignSpec& spec, const RunOptions& options, int task_fd,
                              int result_fd, pid_t parent) {
  for (int sig : {SIGINT, SIGTERM, SIGPIPE}) ::signal(sig, SIG_DFL);
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // a campaign killed outright takes its workers with it
  if (::getppid() != parent) ::_exit(1);
  sim::EstimatorFactory make;
  std::string make_error;
  try {
    make = options.estimators ? options.estimators(spec) : sim::in_process_estimators(spec);
  } catch (const std::exception& e) {
    make_error = std::string("exception making the estimators: ") + e.what();
  }
  std::FILE* in = ::fdopen(task_fd, "r");
  char line[32];
  while (in != nullptr && std::fgets(line, sizeof line, in) != nullptr) {
    const std::size_t index = std::strtoull(line, nullptr, 10);
    const std::string row = make_error.empty()
                                ? run_row(spec, index, make)
                                : sim::campaign_csv_row(sim::campaign_error_row(spec, index, make_error));
    if (!write_all(result_fd, row + "\n")) ::_exit(1);
  }
  ::_exit(0);
}

//! "killed by signal 9 (Killed)" or "exited with status 3".
std::string death_text(int status) {
  if (WIFSIGNALED(status))
    return "killed by signal " + std::to_string(WTERMSIG(status)) + " (" + ::strsignal(WTERMSIG(status)) +
           ")";
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  return "ended";
}

class Pool {
 public:
  Pool(const sim::CampaignSpec& spec, const RunOptions& options, std::deque<std::size_t> pending,
       std::ofstream& out, Progress& progress)
      : spec_(spec), options_(options), pending_(std::move(pending)), out_(out), progress_(progress) {}
  Pool(const Pool&) = delete;
  Pool& operator=(const Pool&) = delete;
  ~Pool() {
    for (Worker& w : workers_) end(w, SIGKILL);
  }

  //! Runs every pending index; false when stopped by a signal.
  Status run() {
    const auto jobs = static_cast<std::size_t>(std::max(1, options_.jobs));
    auto next_progress = Clock::now() + std::chrono::seconds(1);
    while (g_stop_signal == 0) {
      while (!pending_.empty() && workers_.size() < std::min(jobs, pending_.size() + busy())) {
        if (Status st = spawn(); !st) return st;
      }
      hand_out();
      if (workers_.empty()) break;
      wait_for_rows();
      expire_timeouts();
      if (!out_) return failure("cannot write the rows");
      if (Clock::now() >= next_progress && options_.on_progress) {
        report_progress(false);
        next_progress += std::chrono::seconds(1);
      }
    }
    return ok_status();
  }

  void stop_all() {
    for (Worker& w : workers_) end(w, SIGTERM);
    workers_.clear();
  }

  void report_progress(bool final) {
    progress_.elapsed_s = std::chrono::duration<double>(Clock::now() - start_).count();
    progress_.final = final;
    if (options_.on_progress) options_.on_progress(progress_);
  }

 private:
  std::size_t busy() const {
    return static_cast<std::size_t>(
        std::count_if(workers_.begin(), workers_.end(), [](const Worker& w) { return w.run.has_value(); }));
  }

  Status spawn() {
    int task[2];
    int result[2];
    if (::pipe2(task, O_CLOEXEC) != 0) return failure("cannot create a pipe");
    if (::pipe2(result, O_CLOEXEC) != 0) {
      ::close(task[0]);
      ::close(task[1]);
      return failure("cannot create a pipe");
    }
    std::cout.flush();
    std::cerr.flush();
    out_.flush();
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) {
      for (int fd : {task[0], task[1], result[0], result[1]}) ::close(fd);
      return failure("cannot fork a worker");
    }
    if (pid == 0) {
      for (const Worker& w : workers_) {
        if (w.task_fd >= 0) ::close(w.task_fd);
        ::close(w.result_fd);
      }
      ::close(task[1]);
      ::close(result[0]);
      worker_main(spec_, options_, task[0], result[1], parent);
    }
    ::close(task[0]);
    ::close(result[1]);
    ::fcntl(result[0], F_SETFL, ::fcntl(result[0], F_GETFL) | O_NONBLOCK);
    Worker w;
    w.pid = pid;
    w.task_fd = task[1];
    w.result_fd = result[0];
    workers_.push_back(std::move(w));
    return ok_status();
  }

  void hand_out() {
    for (Worker& w : workers_) {
      if (w.run || w.task_fd < 0) continue;
      if (pending_.empty()) {  // nothing left: the worker ends when it reads the end of its pipe
        ::close(w.task_fd);
        w.task_fd = -1;
        continue;
      }
      const std::size_t index = pending_.front();
      if (!write_all(w.task_fd, std::to_string(index) + "\n")) {  // it died: seen at its pipe's end
        ::close(w.task_fd);
        w.task_fd = -1;
        continue;
      }
      pending_.pop_front();
      w.run = index;
      w.deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(options_.run_timeout_s));
    }
  }

  void write_row(const std::string& line, bool error) {
    out_ << line << '\n' << std::flush;  // one whole row at a time: an interruption loses no finished run
    ++progress_.done_now;
    if (error) ++progress_.errors;
  }

  //! Reads what the workers wrote (at most until the nearest deadline, or a second).
  void wait_for_rows() {
    auto now = Clock::now();
    auto until = now + std::chrono::seconds(1);
    std::vector<pollfd> fds;
    for (const Worker& w : workers_) {
      if (w.run) until = std::min(until, w.deadline);
      fds.push_back(pollfd{w.result_fd, POLLIN, 0});
    }
    const auto wait_ms = std::chrono::duration_cast<std::chrono::milliseconds>(until - now).count();
    if (::poll(fds.data(), fds.size(), static_cast<int>(std::max<long long>(0, wait_ms)) + 1) <= 0) return;
    std::vector<std::size_t> dead;
    for (std::size_t i = 0; i < workers_.size(); ++i) {
      if (fds[i].revents == 0) continue;
      if (!read_rows(workers_[i])) dead.push_back(i);
    }
    for (auto it = dead.rbegin(); it != dead.rend(); ++it) {
      Worker& w = workers_[*it];
      int status = 0;
      while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
      }
      w.pid = -1;
      // Stopping (Ctrl-C reaches the workers too): the run is not an error, it is simply not done.
      if (w.run && g_stop_signal == 0) error_row(*w.run, "worker " + death_text(status) + " during the run");
      close_fds(w);
      workers_.erase(workers_.begin() + static_cast<std::ptrdiff_t>(*it));
    }
  }

  //! The whole rows a worker wrote; false at the end of its pipe (it ended).
  bool read_rows(Worker& w) {
    char chunk[65536];
    for (;;) {
      const ssize_t n = ::read(w.result_fd, chunk, sizeof chunk);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return true;  // EAGAIN: all read for now
      if (n == 0) return false;
      w.buffer.append(chunk, static_cast<std::size_t>(n));
      std::size_t start = 0;
      for (std::size_t end; (end = w.buffer.find('\n', start)) != std::string::npos; start = end + 1) {
        const std::string line = w.buffer.substr(start, end - start);
        auto row = sim::parse_campaign_row(line);
        if (row && w.run && row->run == *w.run) {
          write_row(line, !row->error.empty());
        } else if (w.run) {
          error_row(*w.run, "the worker wrote a row that does not read back");
        }
        w.run.reset();
      }
      w.buffer.erase(0, start);
    }
  }

  void expire_timeouts() {
    const auto now = Clock::now();
    for (std::size_t i = workers_.size(); i-- > 0;) {
      Worker& w = workers_[i];
      if (!w.run || now < w.deadline) continue;
      const std::size_t run = *w.run;
      end(w, SIGKILL);
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", options_.run_timeout_s);
      error_row(run, std::string("timeout: no result after ") + limit +
                         " s (--run-timeout); its worker was killed");
      workers_.erase(workers_.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }

  void error_row(std::size_t run, const std::string& message) {
    write_row(sim::campaign_csv_row(sim::campaign_error_row(spec_, run, message)), true);
  }

  static void close_fds(Worker& w) {
    if (w.task_fd >= 0) ::close(w.task_fd);
    if (w.result_fd >= 0) ::close(w.result_fd);
    w.task_fd = w.result_fd = -1;
  }

  //! Sends `sig` to a worker, reaps it and closes its pipes.
  static void end(Worker& w, int sig) {
    if (w.pid > 0) {
      ::kill(w.pid, sig);
      while (::waitpid(w.pid, nullptr, 0) < 0 && errno == EINTR) {
      }
      w.pid = -1;
    }
    close_fds(w);
  }

  const sim::CampaignSpec& spec_;
  const RunOptions& options_;
  std::deque<std::size_t> pending_;
  std::ofstream& out_;
  Progress& progress_;
  std::vector<Worker> workers_;
  Clock::time_point start_ = Clock::now();
};

}  // namespace

Result<RunSummary> run_campaign(const sim::CampaignSpec& spec, const RunOptions& options) {
  RunSummary summary;
  auto pending = prepare_folder(spec, options, summary);
  if (!pending) return pending.error();
  Progress progress;
  progress.total = summary.total;
  progress.done_before = summary.done_before;
  if (!pending->empty()) {
    std::ofstream out(summary.runs_csv, std::ios::app);
    if (!out) return failure(summary.runs_csv + ": cannot write");
    StopSignals signals;
    Pool pool(spec, options, std::deque<std::size_t>(pending->begin(), pending->end()), out, progress);
    Status st = pool.run();
    if (g_stop_signal != 0) {
      pool.stop_all();
      pool.report_progress(true);
      return failure(std::string("interrupted by ") + (g_stop_signal == SIGINT ? "SIGINT" : "SIGTERM") +
                     ": workers stopped, " + std::to_string(progress.done_before + progress.done_now) +
                     " of " + std::to_string(progress.total) + " runs in " + summary.runs_csv +
                     "; the same command continues the campaign");
    }
    if (!st) return failure(summary.runs_csv + ": " + st.error().message);
    pool.report_progress(true);
  }
  // Every row in: runs.csv by run, the file whatever the number of workers or shards.
  auto rows = folder::read_rows(summary.runs_csv, sim::campaign_csv_header(spec), false);
  if (!rows) return rows.error();
  if (rows->size() != summary.total)
    return failure(summary.runs_csv + ": " + std::to_string(rows->size()) + " rows of " +
                   std::to_string(summary.total) + " runs after the campaign");
  if (Status st = folder::write_rows(summary.runs_csv, sim::campaign_csv_header(spec), *rows); !st)
    return st.error();
  summary.errors = static_cast<std::size_t>(
      std::count_if(rows->begin(), rows->end(), [](const folder::Row& r) { return r.error; }));
  return summary;
}

}  // namespace tetra::campaign
