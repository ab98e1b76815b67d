#include "campaign_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include <spdlog/fmt/fmt.h>

#include "gnuplot.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/sim/campaign.hpp"

namespace tetra::cli {

namespace {

using sim::CampaignRow;
using sim::Outcome;

constexpr Outcome kOutcomes[] = {Outcome::kRight, Outcome::kUnisolated, Outcome::kWrong, Outcome::kMissed,
                                 Outcome::kNone};

//! The rows of runs that finished, by run; those that ended in an error go to `errors`.
Result<std::vector<CampaignRow>> read_rows(const std::string& path, std::vector<CampaignRow>& errors) {
  std::ifstream in(path);
  if (!in) return failure(path + ": cannot open");
  std::vector<CampaignRow> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    auto row = sim::parse_campaign_row(line);
    if (row) (row->error.empty() ? rows : errors).push_back(*row);
  }
  for (auto* list : {&rows, &errors}) {
    std::sort(list->begin(), list->end(),
              [](const CampaignRow& a, const CampaignRow& b) { return a.run < b.run; });
  }
  return rows;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

std::string g(double v) {
  return fmt::format("{:.4g}", v);
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
      for (Outcome o : kOutcomes) {
        const auto c = it->second.find(o);
        if (c == it->second.end()) continue;
        cell +=
            (cell.empty() ? "" : ", ") + std::to_string(c->second) + " " + std::string(sim::outcome_name(o));
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
           (det.empty() ? "–" : g(quantile(det, 0.5))) + " | " + (det.empty() ? "–" : g(quantile(det, 1.0))) +
           " | " + std::to_string(iso.size()) + " | " + (iso.empty() ? "–" : g(quantile(iso, 0.5))) + " | " +
           (iso.empty() ? "–" : g(quantile(iso, 1.0))) + " | " +
           (theory.empty() ? "–" : g(quantile(theory, 0.5))) + " |\n";
  }
  return out;
}

Status plot_delays(const std::vector<CampaignRow>& rows, const std::string& png) {
  auto dir = TempDir::create("tetra-campaign");
  if (!dir) return dir.error();
  std::string data;
  for (const CampaignRow& r : rows) {
    if (r.theory_delay_s && r.fdi.detection_delay_s) {
      data += g(*r.theory_delay_s) + ' ' + g(std::max(*r.fdi.detection_delay_s, 1e-2)) + ' ' +
              std::to_string(r.gyro) + '\n';
    }
  }
  if (data.empty()) return ok_status();
  const std::string file = (dir->path() / "delays.dat").string();
  if (Status s = write_text_file(file, data); !s) return s;
  const std::string body =
      "set logscale xy\nset grid\nset key top left\nset xlabel 'CUSUM theory (Siegmund ARL) [s]'\n"
      "set ylabel 'measured detection delay [s] (0 plotted at 0.01)'\n"
      "set title 'bias faults: detection delay against the CUSUM theory'\n"
      "plot " +
      gp_quote(file) +
      " using 1:2:3 with points pt 7 ps 0.8 lc variable title 'runs (colour: gyro)', "
      "x with lines lw 2 dt 2 lc rgb 'black' title 'measured = theory'\n";
  return run_gnuplot(dir->path(), png, 800, 600, body, "report");
}

//! A faulty closed-loop run (open-loop rows have no pointing columns).
bool has_pointing(const CampaignRow& r) {
  return r.kind != "none" && !std::isnan(r.pointing_max_after_deg);
}

Status plot_pointing(const std::vector<CampaignRow>& rows, const std::string& png) {
  auto dir = TempDir::create("tetra-campaign");
  if (!dir) return dir.error();
  std::vector<double> v;
  double bound = 0.0;
  for (const CampaignRow& r : rows) {
    if (!has_pointing(r)) continue;
    v.push_back(r.pointing_max_after_deg);
    bound = r.bound_deg;
  }
  if (v.empty()) return ok_status();
  std::sort(v.begin(), v.end());
  std::string data;
  for (std::size_t i = 0; i < v.size(); ++i) {
    data += g(v[i]) + ' ' + g(static_cast<double>(i + 1) / static_cast<double>(v.size())) + '\n';
  }
  const std::string file = (dir->path() / "pointing.dat").string();
  if (Status s = write_text_file(file, data); !s) return s;
  const std::string body =
      "set logscale x\nset grid\nset key bottom right\nset xlabel 'max pointing error after the fault "
      "[deg]'\n"
      "set ylabel 'fraction of runs'\nset yrange [0:1.02]\n"
      "set title 'pointing error after the fault: distribution over the runs'\n"
      "set arrow from " +
      g(bound) + ", graph 0 to " + g(bound) +
      ", graph 1 nohead dt 2 lw 2\n"
      "plot " +
      gp_quote(file) +
      " using 1:2 with steps lw 2 title 'empirical CDF', 1/0 with lines dt 2 lw 2 lc rgb 'black' title "
      "'bound " +
      g(bound) + " deg'\n";
  return run_gnuplot(dir->path(), png, 800, 600, body, "report");
}

Status plot_outcomes(const std::vector<CampaignRow>& rows, const std::string& png) {
  auto dir = TempDir::create("tetra-campaign");
  if (!dir) return dir.error();
  std::map<std::string, std::map<Outcome, int>> m;  // "kind g#" → outcome counts
  for (const CampaignRow& r : rows) {
    if (r.kind != "none") ++m[r.kind + "-g" + std::to_string(r.gyro)][r.fdi.outcome];
  }
  if (m.empty()) return ok_status();
  std::string data = "case right unisolated wrong missed\n";
  for (const auto& [label, counts] : m) {
    data += label;
    for (Outcome o : {Outcome::kRight, Outcome::kUnisolated, Outcome::kWrong, Outcome::kMissed}) {
      const auto it = counts.find(o);
      data += ' ' + std::to_string(it == counts.end() ? 0 : it->second);
    }
    data += '\n';
  }
  const std::string file = (dir->path() / "outcomes.dat").string();
  if (Status s = write_text_file(file, data); !s) return s;
  const std::string body =
      "set style data histograms\nset style histogram rowstacked\nset style fill solid 0.9 border -1\n"
      "set boxwidth 0.8\nset xtics rotate by -60 font ',8'\nset ylabel 'runs'\nset key outside right\n"
      "set title 'isolation outcome per fault kind and gyro'\nset datafile separator ' '\n"
      "plot " +
      gp_quote(file) +
      " using 2:xtic(1) title 'right' lc rgb '#2ca02c', '' using 3 title 'unisolated' lc rgb '#1f77b4', "
      "'' using 4 title 'wrong' lc rgb '#d62728', '' using 5 title 'missed' lc rgb '#7f7f7f'\n";
  return run_gnuplot(dir->path(), png, 1000, 600, body, "report");
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
  return fmt::format(
      "Max pointing error after the fault [deg]: median {}, 90 % {}, 99 % {}, max {}. Within the bound ({} "
      "deg) "
      "throughout: {} of {} runs. Recovered below the bound by the end: {} (median time {} s); not "
      "recovered: {}.\n",
      g(quantile(max_after, 0.5)), g(quantile(max_after, 0.9)), g(quantile(max_after, 0.99)),
      g(quantile(max_after, 1.0)), g(bound), within, max_after.size(), recover.size(),
      recover.empty() ? "–" : g(quantile(recover, 0.5)), not_recovered);
}

std::string wrong_section(const std::vector<CampaignRow>& rows) {
  std::string out;
  for (const CampaignRow& r : rows) {
    if (r.fdi.outcome != Outcome::kWrong) continue;
    const std::string fault = r.kind == "none" ? std::string("no fault")
                                               : fmt::format("gyro={},kind={},at={},size={}", r.gyro, r.kind,
                                                             g(r.onset_s), g(r.size));
    out += fmt::format("- run {}: {} {}, seed {} → healthy gyro {} isolated at t = {} s\n", r.run, r.scenario,
                       fault, r.seed, r.fdi.wrong_gyro ? std::to_string(*r.fdi.wrong_gyro) : std::string("?"),
                       r.fdi.wrong_at_s ? g(*r.fdi.wrong_at_s) : std::string("?"));
  }
  return out.empty() ? "None.\n" : out;
}

//! Every run that ended in an error, with its case and message (not counted in the sections above).
std::string error_section(const std::vector<CampaignRow>& errors) {
  if (errors.empty()) return "None.\n";
  std::string out =
      "| run | scenario | kind | gyro | onset_s | size | seed | error |\n|---|---|---|---|---|---|---|---|\n";
  for (const CampaignRow& r : errors) {
    out += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", r.run, r.scenario, r.kind, r.gyro,
                       g(r.onset_s), g(r.size), r.seed, r.error);
  }
  return out;
}

}  // namespace

Status write_campaign_report(const std::string& runs_csv, const std::string& out_dir) {
  std::vector<CampaignRow> errors;
  auto rows = read_rows(runs_csv, errors);
  if (!rows) return rows.error();
  int false_alarms = 0;
  double fault_free_s = 0.0;
  for (const CampaignRow& r : *rows) {
    false_alarms += r.fdi.false_alarms;
    fault_free_s += r.fdi.fault_free_s;
  }
  const std::filesystem::path dir(out_dir);
  std::string md = "# Campaign report\n\n" + std::to_string(rows->size()) + " runs (`runs.csv`)" +
                   (errors.empty() ? std::string()
                                   : ", and " + std::to_string(errors.size()) +
                                         " that ended in an error (\"Errors\", not counted below)") +
                   ".\n\n";
  md += "## Isolation outcome (kind × gyro)\n\n" + outcome_matrix(*rows) + "\n![outcomes](outcomes.png)\n\n";
  md += "## Wrong exclusions\n\n" + wrong_section(*rows) + "\n";
  md += "## Detection and isolation delays\n\n" + delay_table(*rows) +
        "\nCUSUM theory: Siegmund's ARL for the parity shift a bias step makes on its gyro "
        "(fdi/include/tetra/fdi/detectors.hpp).\n\n![delays](delay_vs_theory.png)\n\n";
  md += fmt::format(
      "## False alarms\n\n{} detections before the fault onset in {} h of fault-free flight: {} per "
      "hour.\n\n",
      false_alarms, g(fault_free_s / 3600.0),
      fault_free_s > 0.0 ? g(false_alarms / (fault_free_s / 3600.0)) : std::string("–"));
  const bool pointing = std::any_of(rows->begin(), rows->end(), has_pointing);
  md += "## Pointing\n\n" + pointing_section(*rows) + (pointing ? "\n![pointing](pointing_cdf.png)\n" : "");
  md += "\n## Errors\n\n" + error_section(errors);
  if (Status s = write_text_file((dir / "report.md").string(), md); !s) return s;
  if (Status s = plot_delays(*rows, (dir / "delay_vs_theory.png").string()); !s) return s;
  if (Status s = plot_outcomes(*rows, (dir / "outcomes.png").string()); !s) return s;
  return pointing ? plot_pointing(*rows, (dir / "pointing_cdf.png").string()) : ok_status();
}

}  // namespace tetra::cli
