#pragma once
// The report of a campaign (docs/campaign.md, "Output"): report.md with the isolation outcome matrix
// (kind × gyro), every wrong exclusion, delays against the CUSUM theory, false alarms per hour and the
// pointing error distribution; with dispersions or requirements also the statistics with confidence
// (tetra/sim/campaign_statistics.hpp). The plots are returned as gnuplot commands and their data, for the
// caller to draw (the library runs no program).

#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/sim/campaign.hpp"

namespace tetra::sim {

//! One PNG plot: gnuplot commands that read their data from the file named by the gnuplot string
//! variable `datafile` (the caller writes `data` to a file and sets the variable).
struct ReportPlot {
  std::string png;   //!< file name beside report.md
  int width = 800;   //!< [px]
  int height = 600;  //!< [px]
  std::string data;
  std::string body;
};

struct CampaignReport {
  std::string markdown;           //!< report.md
  std::vector<ReportPlot> plots;  //!< in the order report.md shows them; a plot without data is left out
};

struct CampaignReportOptions {
  bool statistics = false;                //!< the statistics sections (a spec with dispersions)
  std::vector<Requirement> requirements;  //!< judged in a section of their own (statistics with them)
};

//! The report's file names beside runs.csv: report.md and its plots (a plot per kind with sizes).
inline constexpr const char* kReportMarkdown = "report.md";
inline constexpr const char* kOutcomePlot = "outcomes.png";
inline constexpr const char* kDelayPlot = "delay_vs_theory.png";
inline constexpr const char* kPointingPlot = "pointing_cdf.png";
//! "detection_vs_size_KIND.png".
std::string size_plot_name(const std::string& kind);
//! Every file a campaign's report may write (whether or not its data leave a plot out): report.md, the
//! plots, a size plot for each fault kind.
std::vector<std::string> campaign_report_files();

//! The options a spec asks for: statistics with dispersions, its requirements.
CampaignReportOptions report_options(const CampaignSpec& spec);

//! The rows of a runs.csv (torn lines skipped), ordered by run.
Result<std::vector<CampaignRow>> read_campaign_rows(const std::string& runs_csv);
//! The report of `rows`.
CampaignReport campaign_report(const std::vector<CampaignRow>& rows, const CampaignReportOptions& options);

//! Text of a number as the report writes it (printf's %.4g).
std::string report_number(double v);
//! The q-quantile of `v` (nearest rank; 0 for none).
double report_quantile(std::vector<double> v, double q);

}  // namespace tetra::sim
