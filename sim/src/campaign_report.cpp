#include "tetra/sim/campaign_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>

#include "tetra/sim/campaign_statistics.hpp"

namespace tetra::sim {

namespace {

constexpr Outcome kReportOutcomes[] = {Outcome::kRight, Outcome::kUnisolated, Outcome::kWrong,
                                       Outcome::kMissed, Outcome::kNone};

std::string g(double v) {
  return report_number(v);
}

std::string outcome_matrix(const std::vector<CampaignRow>& rows) {
  std::map<std::string, std::map<int, std::map<Outcome, int>>> m;
  int max_gyro = 0;
  for (const CampaignRow& r : rows) {
    if (r.kind == "none") continue;
    ++m[r.kind][r.gyro][r.fdi.outcome];
    max_gyro = std::max(max_gyro, r.gyro);
  }
  std::string out = "| kind |";
  for (int gyro = 1; gyro <= max_gyro; ++gyro) out += " gyro " + std::to_string(gyro) + " |";
  out += "\n|---|";
  for (int gyro = 1; gyro <= max_gyro; ++gyro) out += "---|";
  out += '\n';
  for (const auto& [kind, by_gyro] : m) {
    out += "| " + kind + " |";
    for (int gyro = 1; gyro <= max_gyro; ++gyro) {
      const auto it = by_gyro.find(gyro);
      if (it == by_gyro.end()) {
        out += " – |";
        continue;
      }
      std::string cell;
      for (Outcome o : kReportOutcomes) {
        const auto c = it->second.find(o);
        if (c == it->second.end()) continue;
        cell += (cell.empty() ? "" : ", ") + std::to_string(c->second) + " " + std::string(outcome_name(o));
      }
      out += " " + cell + " |";
    }
    out += '\n';
  }
  return out;
}

std::string delay_table(const std::vector<CampaignRow>& rows) {
  std::map<std::string, std::vector<const CampaignRow*>> by_kind;
  for (const CampaignRow& r : rows) {
    if (r.kind != "none") by_kind[r.kind].push_back(&r);
  }
  std::string out =
      "| kind | runs | detected | median detection [s] | max detection [s] | isolated | median isolation [s] "
      "| "
      "max isolation [s] | median CUSUM theory [s] |\n|---|---|---|---|---|---|---|---|---|\n";
  const auto median_max = [](const std::vector<double>& v, double q) {
    return v.empty() ? std::string("–") : g(report_quantile(v, q));
  };
  for (const auto& [kind, list] : by_kind) {
    std::vector<double> det;
    std::vector<double> iso;
    std::vector<double> theory;
    for (const CampaignRow* r : list) {
      if (r->fdi.detection_delay_s) det.push_back(*r->fdi.detection_delay_s);
      if (r->fdi.isolation_delay_s) iso.push_back(*r->fdi.isolation_delay_s);
      if (r->theory_delay_s) theory.push_back(*r->theory_delay_s);
    }
    out += "| " + kind + " | " + std::to_string(list.size()) + " | " + std::to_string(det.size()) + " | " +
           median_max(det, 0.5) + " | " + median_max(det, 1.0) + " | " + std::to_string(iso.size()) + " | " +
           median_max(iso, 0.5) + " | " + median_max(iso, 1.0) + " | " + median_max(theory, 0.5) + " |\n";
  }
  return out;
}

ReportPlot delay_plot(const std::vector<CampaignRow>& rows) {
  ReportPlot plot{kDelayPlot, 800, 600, "", ""};
  for (const CampaignRow& r : rows) {
    if (r.theory_delay_s && r.fdi.detection_delay_s) {
      plot.data += g(*r.theory_delay_s) + ' ' + g(std::max(*r.fdi.detection_delay_s, 1e-2)) + ' ' +
                   std::to_string(r.gyro) + '\n';
    }
  }
  plot.body =
      "set logscale xy\nset grid\nset key top left\nset xlabel 'CUSUM theory (Siegmund ARL) [s]'\n"
      "set ylabel 'measured detection delay [s] (0 plotted at 0.01)'\n"
      "set title 'bias faults: detection delay against the CUSUM theory'\n"
      "plot datafile using 1:2:3 with points pt 7 ps 0.8 lc variable title 'runs (colour: gyro)', "
      "x with lines lw 2 dt 2 lc rgb 'black' title 'measured = theory'\n";
  return plot;
}

//! A faulty closed-loop run (open-loop rows have no pointing columns).
bool has_pointing(const CampaignRow& r) {
  return r.kind != "none" && !std::isnan(r.pointing_max_after_deg);
}

ReportPlot pointing_plot(const std::vector<CampaignRow>& rows) {
  ReportPlot plot{kPointingPlot, 800, 600, "", ""};
  std::vector<double> v;
  double bound = 0.0;
  for (const CampaignRow& r : rows) {
    if (!has_pointing(r)) continue;
    v.push_back(r.pointing_max_after_deg);
    bound = r.bound_deg;
  }
  std::sort(v.begin(), v.end());
  for (std::size_t i = 0; i < v.size(); ++i) {
    plot.data += g(v[i]) + ' ' + g(static_cast<double>(i + 1) / static_cast<double>(v.size())) + '\n';
  }
  plot.body =
      "set logscale x\nset grid\nset key bottom right\nset xlabel 'max pointing error after the fault "
      "[deg]'\n"
      "set ylabel 'fraction of runs'\nset yrange [0:1.02]\n"
      "set title 'pointing error after the fault: distribution over the runs'\n"
      "set arrow from " +
      g(bound) + ", graph 0 to " + g(bound) +
      ", graph 1 nohead dt 2 lw 2\n"
      "plot datafile using 1:2 with steps lw 2 title 'empirical CDF', 1/0 with lines dt 2 lw 2 lc rgb "
      "'black' title 'bound " +
      g(bound) + " deg'\n";
  return plot;
}

ReportPlot outcome_plot(const std::vector<CampaignRow>& rows) {
  ReportPlot plot{kOutcomePlot, 1000, 600, "", ""};
  std::map<std::string, std::map<Outcome, int>> m;  // "kind g#" → outcome counts
  for (const CampaignRow& r : rows) {
    if (r.kind != "none") ++m[r.kind + "-g" + std::to_string(r.gyro)][r.fdi.outcome];
  }
  if (m.empty()) return plot;
  plot.data = "case right unisolated wrong missed\n";
  for (const auto& [label, counts] : m) {
    plot.data += label;
    for (Outcome o : {Outcome::kRight, Outcome::kUnisolated, Outcome::kWrong, Outcome::kMissed}) {
      const auto it = counts.find(o);
      plot.data += ' ' + std::to_string(it == counts.end() ? 0 : it->second);
    }
    plot.data += '\n';
  }
  plot.body =
      "set style data histograms\nset style histogram rowstacked\nset style fill solid 0.9 border -1\n"
      "set boxwidth 0.8\nset xtics rotate by -60 font ',8'\nset ylabel 'runs'\nset key outside right\n"
      "set title 'isolation outcome per fault kind and gyro'\nset datafile separator ' '\n"
      "plot datafile using 2:xtic(1) title 'right' lc rgb '#2ca02c', '' using 3 title 'unisolated' lc rgb "
      "'#1f77b4', '' using 4 title 'wrong' lc rgb '#d62728', '' using 5 title 'missed' lc rgb '#7f7f7f'\n";
  return plot;
}

std::string pointing_section(const std::vector<CampaignRow>& rows) {
  std::vector<double> max_after;
  std::vector<double> recover;
  double bound = 0.0;
  std::size_t within = 0;
  std::size_t not_recovered = 0;
  for (const CampaignRow& r : rows) {
    if (!has_pointing(r)) continue;
    max_after.push_back(r.pointing_max_after_deg);
    bound = r.bound_deg;
    if (r.pointing_max_after_deg < r.bound_deg) ++within;
    if (r.recover_s) {
      recover.push_back(*r.recover_s);
    } else {
      ++not_recovered;
    }
  }
  if (max_after.empty()) return "No faulty closed-loop runs (open loop: nothing steers, no pointing).\n";
  return "Max pointing error after the fault [deg]: median " + g(report_quantile(max_after, 0.5)) +
         ", 90 % " + g(report_quantile(max_after, 0.9)) + ", 99 % " + g(report_quantile(max_after, 0.99)) +
         ", max " + g(report_quantile(max_after, 1.0)) + ". Within the bound (" + g(bound) +
         " deg) throughout: " + std::to_string(within) + " of " + std::to_string(max_after.size()) +
         " runs. Recovered below the bound by the end: " + std::to_string(recover.size()) + " (median time " +
         (recover.empty() ? std::string("–") : g(report_quantile(recover, 0.5))) +
         " s); not recovered: " + std::to_string(not_recovered) + ".\n";
}

std::string wrong_section(const std::vector<CampaignRow>& rows) {
  std::string out;
  for (const CampaignRow& r : rows) {
    if (r.fdi.outcome != Outcome::kWrong) continue;
    const std::string fault = r.kind == "none" ? std::string("no fault")
                                               : "gyro=" + std::to_string(r.gyro) + ",kind=" + r.kind +
                                                     ",at=" + g(r.onset_s) + ",size=" + g(r.size);
    out += "- run " + std::to_string(r.run) + ": " + r.scenario + " " + fault + ", seed " +
           std::to_string(r.seed) + " → healthy gyro " +
           (r.fdi.wrong_gyro ? std::to_string(*r.fdi.wrong_gyro) : std::string("?")) +
           " isolated at t = " + (r.fdi.wrong_at_s ? g(*r.fdi.wrong_at_s) : std::string("?")) + " s\n";
  }
  return out.empty() ? "None.\n" : out;
}

}  // namespace

std::string report_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

double report_quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

std::string size_plot_name(const std::string& kind) {
  return "detection_vs_size_" + kind + ".png";
}

std::vector<std::string> campaign_report_files() {
  std::vector<std::string> files{kReportMarkdown, kOutcomePlot, kDelayPlot, kPointingPlot};
  for (int k = 0; k <= static_cast<int>(FaultKind::kInvalid); ++k)
    files.push_back(size_plot_name(std::string(fault_kind_name(static_cast<FaultKind>(k)))));
  return files;
}

CampaignReportOptions report_options(const CampaignSpec& spec) {
  return {!spec.dispersions.empty(), spec.requirements};
}

Result<std::vector<CampaignRow>> read_campaign_rows(const std::string& path) {
  std::ifstream in(path);
  if (!in) return failure(path + ": cannot open");
  std::vector<CampaignRow> rows;
  std::string header;
  std::getline(in, header);
  for (std::string line; std::getline(in, line);) {
    auto row = parse_campaign_row(line, header);
    if (row) rows.push_back(*row);
  }
  std::sort(rows.begin(), rows.end(),
            [](const CampaignRow& a, const CampaignRow& b) { return a.run < b.run; });
  return rows;
}

namespace {

//! Every run that ended in an error, with its case and message (not counted in the other sections).
std::string error_section(const std::vector<CampaignRow>& errors) {
  if (errors.empty()) return "None.\n";
  std::string out =
      "| run | scenario | kind | gyro | onset_s | size | seed | error |\n|---|---|---|---|---|---|---|---|\n";
  for (const CampaignRow& r : errors) {
    out += "| " + std::to_string(r.run) + " | " + r.scenario + " | " + r.kind + " | " +
           std::to_string(r.gyro) + " | " + g(r.onset_s) + " | " + g(r.size) + " | " +
           std::to_string(r.seed) + " | " + r.error + " |\n";
  }
  return out;
}

}  // namespace

CampaignReport campaign_report(const std::vector<CampaignRow>& all_rows,
                               const CampaignReportOptions& options) {
  std::vector<CampaignRow> rows;
  std::vector<CampaignRow> errors;
  for (const CampaignRow& r : all_rows) (r.error.empty() ? rows : errors).push_back(r);
  int false_alarms = 0;
  double fault_free_s = 0.0;
  for (const CampaignRow& r : rows) {
    false_alarms += r.fdi.false_alarms;
    fault_free_s += r.fdi.fault_free_s;
  }
  CampaignReport report;
  std::string& md = report.markdown;
  md = "# Campaign report\n\n" + std::to_string(rows.size()) + " runs (`runs.csv`)" +
       (errors.empty() ? std::string()
                       : ", and " + std::to_string(errors.size()) +
                             " that ended in an error (\"Errors\", not counted below)") +
       ".\n\n";
  md += "## Isolation outcome (kind × gyro)\n\n" + outcome_matrix(rows) + "\n![outcomes](" +
        std::string(kOutcomePlot) + ")\n\n";
  md += "## Wrong exclusions\n\n" + wrong_section(rows) + "\n";
  md += "## Detection and isolation delays\n\n" + delay_table(rows) +
        "\nCUSUM theory: Siegmund's ARL for the parity shift a bias step makes on its gyro "
        "(fdi/include/tetra/fdi/detectors.hpp).\n\n![delays](" +
        std::string(kDelayPlot) + ")\n\n";
  md += "## False alarms\n\n" + std::to_string(false_alarms) + " detections before the fault onset in " +
        g(fault_free_s / 3600.0) + " h of fault-free flight: " +
        (fault_free_s > 0.0 ? g(false_alarms / (fault_free_s / 3600.0)) : std::string("–")) +
        " per hour.\n\n";
  const bool pointing = std::any_of(rows.begin(), rows.end(), has_pointing);
  md += "## Pointing\n\n" + pointing_section(rows) +
        (pointing ? "\n![pointing](" + std::string(kPointingPlot) + ")\n" : std::string());
  md += "\n## Errors\n\n" + error_section(errors);
  for (ReportPlot plot : {delay_plot(rows), outcome_plot(rows), pointing_plot(rows)}) {
    if (!plot.data.empty()) report.plots.push_back(std::move(plot));
  }
  if (options.statistics || !options.requirements.empty()) add_statistics(rows, report);
  if (!options.requirements.empty()) report.markdown += requirements_section(options.requirements, rows);
  return report;
}

}  // namespace tetra::sim
