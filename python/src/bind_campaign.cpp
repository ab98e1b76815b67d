// tetra.campaign: a fault-injection campaign in process (docs/campaign.md), its rows as CSV text that the
// package turns into a pandas DataFrame (the columns of runs.csv).
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "common.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/campaign_report.hpp"

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
  for (const std::size_t r : *runs) {
    if (r >= count)
      throw py::value_error("runs: run " + std::to_string(r) + " is not in the matrix (0.." +
                            std::to_string(count - 1) + ")");
  }
  return *runs;
}

//! One CSV row per run, the GIL released: a run that fails is an error row, as `tetra campaign` writes it.
std::vector<std::string> campaign_rows(const sim::CampaignSpec& spec,
                                       const std::optional<std::vector<std::size_t>>& runs) {
  if (spec.target != sim::CampaignTarget::kInProcess)
    throw py::value_error("target: Python runs campaigns in process only (`tetra campaign` runs target dds)");
  const std::vector<std::size_t> indices = campaign_indices(spec, runs);
  std::vector<std::string> lines;
  py::gil_scoped_release release;
  const sim::EstimatorFactory make = sim::in_process_estimators(spec);
  for (const std::size_t r : indices)
    lines.push_back(sim::campaign_csv_row(sim::campaign_run_row(spec, r, make)));
  return lines;
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
  m.def("_campaign_rows", &campaign_rows, "spec"_a, "runs"_a,
        "Runs the cases (all, or the run ids given) one after the other, the GIL released; one CSV row each "
        "(a run that fails is an error row).");
  m.def("_campaign_report", &campaign_report_markdown, "spec"_a, "csv"_a,
        "report.md of runs.csv's text, as `tetra campaign` writes it (without drawing the plots).");
}

}  // namespace tetra::python
