#include "tetra/report/campaign_report.hpp"

#include <filesystem>

#include "tetra/core/csv.hpp"
#include "tetra/report/gnuplot.hpp"

namespace tetra::report {

Status write_campaign_report(const std::string& runs_csv, const std::string& out_dir,
                             const sim::CampaignReportOptions& options) {
  auto rows = sim::read_campaign_rows(runs_csv);
  if (!rows) return rows.error();
  const sim::CampaignReport report = sim::campaign_report(*rows, options);
  const std::filesystem::path dir(out_dir);
  if (Status s = write_text_file((dir / sim::kReportMarkdown).string(), report.markdown); !s) return s;
  for (const sim::ReportPlot& plot : report.plots) {
    auto tmp = TempDir::create("tetra-campaign");
    if (!tmp) return tmp.error();
    const std::string data = (tmp->path() / "plot.dat").string();
    if (Status s = write_text_file(data, plot.data); !s) return s;
    if (Status s = run_gnuplot(tmp->path(), (dir / plot.png).string(), plot.width, plot.height,
                               "datafile = " + gp_quote(data) + "\n" + plot.body, "report");
        !s)
      return s;
  }
  return ok_status();
}

Status write_campaign_report(const sim::CampaignSpec& spec, const std::string& out_dir) {
  return write_campaign_report((std::filesystem::path(out_dir) / "runs.csv").string(), out_dir,
                               sim::report_options(spec));
}

}  // namespace tetra::report
