// tetra.campaign: a fault-injection campaign in process (docs/campaign.md), its rows as CSV text that the
// package turns into a pandas DataFrame (the columns of runs.csv).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <pybind11/stl.h>

#include "common.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/campaign_report.hpp"
#include "watch.hpp"

namespace tetra::python {

using namespace pybind11::literals;

void bind_campaign_runs(py::module_& m);

void bind_campaign(py::module_& m) {
  py::class_<sim::CampaignSpec>(
      m, "CampaignSpec",
      "A campaign's matrix (docs/campaign.md): scenarios × kinds × gyros × onsets × "
      "sizes × seeds. Made by tetra.campaign_spec from a file or a dict.")
      .def_property_readonly(
          "runs", [](const sim::CampaignSpec& s) { return take(sim::campaign_run_count(s)); },
          "The number of runs of the matrix.")
      .def_property_readonly(
          "closed_loop", [](const sim::CampaignSpec& s) { return s.loop == sim::CampaignLoop::kClosed; },
          "True: closed loop (pointing columns filled); False: open loop.")
      .def_property_readonly(
          "in_process",
          [](const sim::CampaignSpec& s) { return s.target == sim::CampaignTarget::kInProcess; },
          "True when the spec's target is the pipeline in process (the only target Python runs).")
      .def_readonly("scenario_paths", &sim::CampaignSpec::scenario_paths,
                    "Scenario files or built-in names.");
  m.def(
      "_read_campaign_spec", [](const std::string& path) { return take(sim::read_campaign_spec(path)); },
      "path"_a);
  m.def(
      "_parse_campaign_spec",
      [](const std::string& text, const std::string& source, const std::string& base_dir) {
        return take(sim::parse_campaign_spec(text, source, base_dir));
      },
      "text"_a, "source"_a, "base_dir"_a);
  m.def(
      "_campaign_csv_header", [](const sim::CampaignSpec& spec) { return sim::campaign_csv_header(spec); },
      "spec"_a);
  bind_campaign_runs(m);
}

namespace {

//! The run ids to run: all of the matrix, or those given (each checked against it).
std::vector<std::size_t> campaign_indices(const sim::CampaignSpec& spec,
                                          const std::optional<std::vector<std::size_t>>& runs) {
  const std::size_t count = take(sim::campaign_run_count(spec));
  std::vector<std::size_t> indices;
  if (!runs) {
    for (std::size_t r = 0; r < count; ++r) indices.push_back(r);
    return indices;
  }
  std::vector<bool> seen(count, false);
  for (const std::size_t r : *runs) {
    if (r >= count)
      throw py::value_error("runs: run " + std::to_string(r) + " is not in the matrix (0.." +
                            std::to_string(count - 1) + ")");
    if (seen[r]) throw py::value_error("runs: run " + std::to_string(r) + " is given twice");
    seen[r] = true;
  }
  return *runs;
}

//! Runs the cases `indices`, `jobs` at a time, into `lines` (one CSV row each, in the order of
//! `indices`; a run that fails is an error row, as `tetra campaign` writes it). Called with the GIL
//! released: the watch is polled from this thread (between the epochs of a run with one job; every 5 ms
//! while the workers run with more). Once it asks to stop, the runs under way are dropped, not written.
void run_cases(const sim::CampaignSpec& spec, const std::vector<std::size_t>& indices, int jobs, Watch& watch,
               std::vector<std::optional<std::string>>& lines) {
  const sim::EstimatorFactory make = sim::in_process_estimators(spec);
  const std::size_t total = indices.size();
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> finished{0};
  std::atomic<bool> stop{false};
  auto run_from = [&](Interrupt& interrupt) {
    for (std::size_t i = next.fetch_add(1); i < total && !stop.load(); i = next.fetch_add(1)) {
      const sim::CampaignRow row = sim::campaign_run_row(spec, indices[i], make, &interrupt);
      if (interrupt.stopped()) return;  // the run it stopped is no row
      lines[i] = sim::campaign_csv_row(row);
      finished.fetch_add(1);
    }
  };
  if (jobs == 1) {
    Interrupt interrupt([&](std::size_t, std::size_t) { return watch.poll(finished.load(), total); });
    run_from(interrupt);
    return;
  }
  const auto workers = static_cast<std::size_t>(std::min<std::size_t>(static_cast<std::size_t>(jobs), total));
  std::atomic<std::size_t> running{0};
  std::vector<std::exception_ptr> failures(workers);
  std::vector<std::thread> threads;
  try {
    for (std::size_t w = 0; w < workers; ++w) {
      running.fetch_add(1);
      threads.emplace_back([&, w] {
        try {
          Interrupt interrupt([&](std::size_t, std::size_t) { return stop.load(); });
          run_from(interrupt);
        } catch (...) {
          failures[w] = std::current_exception();
          stop.store(true);
        }
        running.fetch_sub(1);
      });
    }
  } catch (...) {  // a thread that could not start: the others stop, then the error is raised
    running.fetch_sub(1);
    stop.store(true);
    for (auto& t : threads) t.join();
    throw;
  }
  while (running.load() > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (!stop.load() && watch.poll(finished.load(), total)) stop.store(true);
  }
  for (auto& t : threads) t.join();
  for (const auto& f : failures)
    if (f) std::rethrow_exception(f);
}

//! The CSV rows of the runs done (in run order) and the exception that stopped the campaign (None when
//! every run ran): an interrupted campaign returns the rows it has, as the command keeps them to resume.
py::tuple campaign_rows(const sim::CampaignSpec& spec, const std::optional<std::vector<std::size_t>>& runs,
                        int jobs, const py::object& progress) {
  if (spec.target != sim::CampaignTarget::kInProcess)
    throw py::value_error("target: Python runs campaigns in process only (`tetra campaign` runs target dds)");
  if (jobs < 1) throw py::value_error("jobs: must be at least 1");
  const std::vector<std::size_t> indices = campaign_indices(spec, runs);
  std::vector<std::optional<std::string>> lines(indices.size());
  Watch watch(progress);
  {
    py::gil_scoped_release release;
    run_cases(spec, indices, jobs, watch, lines);
  }
  py::list done;
  for (const auto& line : lines)
    if (line) done.append(*line);
  if (!watch.stopped()) watch.done(indices.size(), indices.size());
  return py::make_tuple(done, watch.pending());
}

//! report.md of the rows in `csv` (runs.csv's text), with the statistics and requirements the spec asks for.
std::string campaign_report_markdown(const sim::CampaignSpec& spec, const std::string& csv) {
  const std::string header = sim::campaign_csv_header(spec);
  std::vector<sim::CampaignRow> rows;
  std::size_t begin = csv.find('\n');
  while (begin != std::string::npos && begin + 1 < csv.size()) {
    const std::size_t end = csv.find('\n', begin + 1);
    const std::string line = csv.substr(begin + 1, end == std::string::npos ? end : end - begin - 1);
    if (auto row = sim::parse_campaign_row(line, header)) rows.push_back(*row);
    begin = end;
  }
  std::sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.run < b.run; });
  return sim::campaign_report(rows, sim::report_options(spec)).markdown;
}

}  // namespace

void bind_campaign_runs(py::module_& m) {
  m.def("_campaign_rows", &campaign_rows, "spec"_a, "runs"_a, "jobs"_a, "progress"_a,
        "Runs the cases (all, or the run ids given), `jobs` at a time, the GIL released: (the CSV rows of "
        "the runs done, in the order given; the exception that stopped it, or None).");
  m.def("_campaign_report", &campaign_report_markdown, "spec"_a, "csv"_a,
        "report.md of runs.csv's text, as `tetra campaign` writes it (without drawing the plots).");
}

}  // namespace tetra::python
