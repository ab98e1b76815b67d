// tetra.campaign: a fault-injection campaign in process (docs/campaign.md), its rows as CSV text that the
// package turns into a pandas DataFrame (the columns of runs.csv).
#include <optional>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "common.hpp"
#include "tetra/sim/campaign.hpp"

namespace tetra::python {

using namespace pybind11::literals;

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
  m.def(
      "_campaign_rows",
      [](const sim::CampaignSpec& spec, const std::optional<std::vector<std::size_t>>& runs) {
        if (spec.target != sim::CampaignTarget::kInProcess)
          throw py::value_error(
              "target: Python runs campaigns in process only (`tetra campaign` runs target dds)");
        const std::size_t count = take(sim::campaign_run_count(spec));
        std::vector<std::size_t> indices;
        if (runs) {
          for (const std::size_t r : *runs) {
            if (r >= count)
              throw py::value_error("runs: run " + std::to_string(r) + " is not in the matrix (0.." +
                                    std::to_string(count - 1) + ")");
          }
          indices = *runs;
        } else {
          for (std::size_t r = 0; r < count; ++r) indices.push_back(r);
        }
        std::vector<std::string> lines;
        std::optional<Error> failed;
        {
          py::gil_scoped_release release;
          for (const std::size_t r : indices) {
            auto row = sim::run_campaign_case(spec, sim::campaign_case(spec, r));
            if (!row) {
              failed = row.error();
              break;
            }
            lines.push_back(sim::campaign_csv_row(*row));
          }
        }
        if (failed) raise(*failed);
        return lines;
      },
      "spec"_a, "runs"_a,
      "Runs the cases (all, or the run ids given) one after the other, the GIL released; one CSV row each.");
}

}  // namespace tetra::python
