// libFuzzer target: the campaign spec reader (sim/campaign.hpp) on arbitrary bytes. A refused spec is one
// error line; an accepted one has a bounded matrix whose cases are made on demand, and the row a case
// writes (its error row: the case's columns) reads back under the spec's header and passes the spec's
// own row check (sim::check_campaign_row), as `campaign merge` reads it.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/campaign_report.hpp"

namespace {

// Run `index` of `spec`: its error row written, read back and checked against the matrix.
void check_case(const tetra::sim::CampaignSpec& spec, std::size_t index) {
  const tetra::sim::CampaignRow row =
      tetra::sim::campaign_error_row(spec, index, "fuzz, a message\nof two lines");
  const std::string line = tetra::sim::campaign_csv_row(row);
  TETRA_FUZZ_CHECK(line.find('\n') == std::string::npos);
  const auto back = tetra::sim::parse_campaign_row(line, tetra::sim::campaign_csv_header(spec));
  if (!back) tetra::fuzz::check_error_message(back.error());
  TETRA_FUZZ_CHECK(back.ok());
  TETRA_FUZZ_CHECK(back->run == index);
  const tetra::Status checked = tetra::sim::check_campaign_row(spec, *back);
  if (!checked) tetra::fuzz::check_error_message(checked.error());
  TETRA_FUZZ_CHECK(checked.ok());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // Scenario files resolve against a folder that does not exist: only the built-in scenarios read.
  const auto spec = tetra::sim::parse_campaign_spec(text, "fuzz.yaml", "/nonexistent-tetra-fuzz");
  if (!spec) {
    tetra::fuzz::check_error_message(spec.error());
    return 0;
  }
  const auto runs = tetra::sim::campaign_run_count(*spec);
  if (!runs) {
    tetra::fuzz::check_error_message(runs.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(*runs >= 1 && *runs <= tetra::sim::kMaxCampaignRuns);
  for (const std::size_t index : {std::size_t{0}, *runs / 2, *runs - 1}) check_case(*spec, index);
  const tetra::sim::CampaignReportOptions options = tetra::sim::report_options(*spec);
  TETRA_FUZZ_CHECK(options.requirements.size() == spec->requirements.size());
  return 0;
}
