#include "tetra/sim/campaign_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "tetra/sim/statistics.hpp"

namespace tetra::sim {

namespace {

std::string num(double v) {
  return report_number(v);
}

std::string interval_text(const Interval& i) {
  return "[" + num(i.lower) + ", " + num(i.upper) + "]";
}

bool faulty(const CampaignRow& r) {
  return r.kind != "none";
}

//! The runs a requirement counts and whether each has its event.
struct Selection {
  std::vector<const CampaignRow*> rows;
  bool (*event)(const CampaignRow&) = nullptr;
};

bool detected(const CampaignRow& r) {
  return r.fdi.detection_delay_s.has_value();
}

//! The first isolation after the onset names the faulty gyro.
bool isolated_right(const CampaignRow& r) {
  return r.fdi.isolated_gyro && *r.fdi.isolated_gyro == r.gyro;
}

bool wrong_exclusion(const CampaignRow& r) {
  return r.fdi.wrong_gyro.has_value();
}

Selection select(const Requirement& q, const std::vector<CampaignRow>& rows) {
  Selection s;
  const bool all_runs = q.metric == RequirementMetric::kWrongExclusionRate ||
                        q.metric == RequirementMetric::kFalseAlarmsPerHour;
  for (const CampaignRow& r : rows) {
    if ((all_runs || faulty(r)) && (q.kind.empty() || r.kind == q.kind)) s.rows.push_back(&r);
  }
  switch (q.metric) {
    case RequirementMetric::kRightRate:
      s.event = [](const CampaignRow& r) { return r.fdi.outcome == Outcome::kRight; };
      break;
    case RequirementMetric::kWrongRate:
      s.event = [](const CampaignRow& r) { return r.fdi.outcome == Outcome::kWrong; };
      break;
    case RequirementMetric::kUnisolatedRate:
      s.event = [](const CampaignRow& r) { return r.fdi.outcome == Outcome::kUnisolated; };
      break;
    case RequirementMetric::kMissedRate:
      s.event = [](const CampaignRow& r) { return r.fdi.outcome == Outcome::kMissed; };
      break;
    case RequirementMetric::kDetectionRate:
      s.event = detected;
      break;
    case RequirementMetric::kIsolationRate:
      s.event = isolated_right;
      break;
    case RequirementMetric::kWrongExclusionRate:
    case RequirementMetric::kFalseAlarmsPerHour:
      s.event = wrong_exclusion;
      break;
  }
  return s;
}

RequirementJudgement judge_false_alarms(const Requirement& q, const Selection& s) {
  RequirementJudgement j;
  double seconds = 0.0;
  for (const CampaignRow* r : s.rows) {
    j.events += static_cast<std::uint64_t>(std::max(0, r->fdi.false_alarms));
    seconds += r->fdi.fault_free_s;
  }
  j.trials = seconds / 3600.0;
  if (!(j.trials > 0.0)) {
    j.estimate = j.lower = j.upper = std::numeric_limits<double>::quiet_NaN();
    return j;
  }
  j.estimate = static_cast<double>(j.events) / j.trials;
  j.lower = garwood_lower(j.events, q.confidence) / j.trials;
  j.upper = garwood_upper(j.events, q.confidence) / j.trials;
  const bool pass = q.below ? j.upper < q.bound : j.lower > q.bound;
  const bool fail = q.below ? j.lower > q.bound : j.upper < q.bound;
  j.verdict = pass ? Verdict::kPass : fail ? Verdict::kFail : Verdict::kUndecided;
  if (j.verdict == Verdict::kUndecided && q.below) {
    // Hours at which the bound is met with no further false alarm, in runs of the mean fault-free time.
    const double hours = garwood_upper(j.events, q.confidence) / q.bound - j.trials;
    const double per_run = j.trials / static_cast<double>(s.rows.size());
    const double runs = std::ceil(hours / per_run);
    if (runs < static_cast<double>(kMaxFurtherTrials)) j.further_runs = static_cast<std::uint64_t>(runs);
  }
  return j;
}

}  // namespace

RequirementJudgement judge_requirement(const Requirement& q, const std::vector<CampaignRow>& rows) {
  const Selection s = select(q, rows);
  if (q.metric == RequirementMetric::kFalseAlarmsPerHour) return judge_false_alarms(q, s);
  RequirementJudgement j;
  const auto n = static_cast<std::uint64_t>(s.rows.size());
  for (const CampaignRow* r : s.rows) j.events += s.event(*r) ? 1 : 0;
  j.trials = static_cast<double>(n);
  if (n == 0) {
    j.estimate = j.lower = j.upper = std::numeric_limits<double>::quiet_NaN();
  } else {
    j.estimate = static_cast<double>(j.events) / j.trials;
    j.lower = clopper_pearson_lower(j.events, n, q.confidence);
    j.upper = clopper_pearson_upper(j.events, n, q.confidence);
    const bool pass = q.below ? j.upper < q.bound : j.lower > q.bound;
    const bool fail = q.below ? j.lower > q.bound : j.upper < q.bound;
    j.verdict = pass ? Verdict::kPass : fail ? Verdict::kFail : Verdict::kUndecided;
  }
  if (j.verdict == Verdict::kUndecided) {
    j.further_runs = q.below ? further_trials_below(j.events, n, q.bound, q.confidence)
                             : further_trials_above(j.events, n, q.bound, q.confidence);
  }
  return j;
}

std::string requirements_section(const std::vector<Requirement>& requirements,
                                 const std::vector<CampaignRow>& rows) {
  std::string md =
      "## Requirements\n\nEach judged on its one-sided bound at its confidence (Clopper–Pearson for rates, "
      "Garwood for false alarms per hour): pass when the bound is on the required side, fail when the "
      "opposite bound is on the wrong side, otherwise not yet decidable, with the further runs that could "
      "decide it (for `<`: none of them with the event; for `>`: every one with it; false alarms: at the "
      "mean fault-free time per run).\n\n"
      "| requirement | observed | estimate | one-sided bounds | verdict | further runs |\n"
      "|---|---|---|---|---|---|\n";
  for (const Requirement& q : requirements) {
    const RequirementJudgement j = judge_requirement(q, rows);
    const bool fa = q.metric == RequirementMetric::kFalseAlarmsPerHour;
    const std::string observed =
        fa ? std::to_string(j.events) + " in " + num(j.trials) + " h"
           : std::to_string(j.events) + " of " + std::to_string(static_cast<long long>(j.trials)) + " runs";
    const std::string verdict = j.verdict == Verdict::kPass   ? "**pass**"
                                : j.verdict == Verdict::kFail ? "**fail**"
                                                              : "not yet decidable";
    std::string further = "–";
    if (j.verdict == Verdict::kUndecided)
      further = j.further_runs ? std::to_string(*j.further_runs) : std::string("beyond reach");
    md += "| `" + q.text + "` | " + observed + " | " + num(j.estimate) + " | " + num(j.lower) + " to " +
          num(j.upper) + " | " + verdict + " | " + further + " |\n";
  }
  return md + "\n";
}

namespace {

std::string rates_section(const std::vector<CampaignRow>& rows) {
  std::uint64_t n_faulty = 0;
  std::map<Outcome, std::uint64_t> counts;
  std::uint64_t n_detected = 0;
  std::uint64_t n_isolated = 0;
  std::uint64_t n_wrong_exclusion = 0;
  for (const CampaignRow& r : rows) {
    n_wrong_exclusion += wrong_exclusion(r) ? 1 : 0;
    if (!faulty(r)) continue;
    ++n_faulty;
    ++counts[r.fdi.outcome];
    n_detected += detected(r) ? 1 : 0;
    n_isolated += isolated_right(r) ? 1 : 0;
  }
  std::string md =
      "### Rates\n\nClopper–Pearson (exact binomial) intervals, two-sided 95 %.\n\n"
      "| rate | runs | of | estimate | 95 % interval |\n|---|---|---|---|---|\n";
  const auto line = [&](const std::string& name, std::uint64_t k, std::uint64_t n) {
    if (n == 0) return "| " + name + " | 0 | 0 | – | – |\n";
    return "| " + name + " | " + std::to_string(k) + " | " + std::to_string(n) + " | " +
           num(static_cast<double>(k) / static_cast<double>(n)) + " | " +
           interval_text(clopper_pearson(k, n, kReportConfidence)) + " |\n";
  };
  for (Outcome o : {Outcome::kRight, Outcome::kUnisolated, Outcome::kWrong, Outcome::kMissed})
    md += line(std::string(outcome_name(o)) + " (faulty runs)", counts[o], n_faulty);
  md += line("detected (faulty runs)", n_detected, n_faulty);
  md += line("isolated the faulty gyro (faulty runs)", n_isolated, n_faulty);
  md += line("wrong exclusion (all runs)", n_wrong_exclusion, rows.size());
  return md + "\n";
}

std::string false_alarm_section(const std::vector<CampaignRow>& rows) {
  std::uint64_t k = 0;
  double seconds = 0.0;
  for (const CampaignRow& r : rows) {
    k += static_cast<std::uint64_t>(std::max(0, r.fdi.false_alarms));
    seconds += r.fdi.fault_free_s;
  }
  const double hours = seconds / 3600.0;
  if (!(hours > 0.0)) return "### False alarms per hour\n\nNo fault-free flight.\n\n";
  const Interval i = garwood(k, kReportConfidence);
  return "### False alarms per hour\n\n" + std::to_string(k) + " in " + num(hours) +
         " h: " + num(static_cast<double>(k) / hours) + " per hour, 95 % interval [" + num(i.lower / hours) +
         ", " + num(i.upper / hours) + "] per hour (Garwood, exact Poisson).\n\n";
}

//! The bins of |size| of one kind's runs: each distinct size its own when there are at most kBins of
//! them, else kBins bins of equal width (in log when the sizes span a decade or more).
constexpr std::size_t kBins = 8;

struct SizeBin {
  double lo = 0.0, hi = 0.0, x = 0.0;
  std::uint64_t n = 0, detected = 0, isolated = 0;
};

std::pair<std::vector<SizeBin>, bool> size_bins(const std::vector<const CampaignRow*>& runs) {
  std::set<double> distinct;
  for (const CampaignRow* r : runs) distinct.insert(std::abs(r->size));
  std::vector<SizeBin> bins;
  const double lo = *distinct.begin();
  const double hi = *distinct.rbegin();
  const bool log = lo > 0.0 && hi / lo >= 10.0 && distinct.size() > kBins;
  if (distinct.size() <= kBins) {
    for (double v : distinct) bins.push_back({v, v, v, 0, 0, 0});
  } else {
    for (std::size_t b = 0; b < kBins; ++b) {
      const double f0 = static_cast<double>(b) / kBins;
      const double f1 = static_cast<double>(b + 1) / kBins;
      SizeBin bin;
      bin.lo = log ? lo * std::pow(hi / lo, f0) : lo + (hi - lo) * f0;
      bin.hi = log ? lo * std::pow(hi / lo, f1) : lo + (hi - lo) * f1;
      bin.x = log ? std::sqrt(bin.lo * bin.hi) : 0.5 * (bin.lo + bin.hi);
      bins.push_back(bin);
    }
  }
  for (const CampaignRow* r : runs) {
    const double v = std::abs(r->size);
    std::size_t b = 0;
    while (b + 1 < bins.size() && v > bins[b].hi) ++b;
    ++bins[b].n;
    bins[b].detected += detected(*r) ? 1 : 0;
    bins[b].isolated += isolated_right(*r) ? 1 : 0;
  }
  return {bins, log};
}

void size_curves(const std::vector<CampaignRow>& rows, CampaignReport& report) {
  std::map<std::string, std::vector<const CampaignRow*>> by_kind;
  for (const CampaignRow& r : rows) {
    const auto kind = fault_kind_from_name(r.kind);
    if (faulty(r) && kind && kind_takes_size(*kind)) by_kind[r.kind].push_back(&r);
  }
  std::string& md = report.markdown;
  md += "### Detection and isolation against fault size\n\n";
  if (by_kind.empty()) {
    md += "No fault kind with a size.\n\n";
    return;
  }
  md +=
      "Per kind, the runs binned by |size| (the kind's unit, docs/sim.md); probability of a detection and "
      "of isolating the faulty gyro, with 95 % Clopper–Pearson intervals.\n\n"
      "| kind | \\|size\\| | runs | detected | P(detect) 95 % | isolated | P(isolate) 95 % |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const auto& [kind, runs] : by_kind) {
    const auto [bins, log] = size_bins(runs);
    ReportPlot plot{size_plot_name(kind), 800, 600, "", ""};
    for (const SizeBin& b : bins) {
      if (b.n == 0) continue;
      const Interval d = clopper_pearson(b.detected, b.n, kReportConfidence);
      const Interval i = clopper_pearson(b.isolated, b.n, kReportConfidence);
      const double pd = static_cast<double>(b.detected) / static_cast<double>(b.n);
      const double pi = static_cast<double>(b.isolated) / static_cast<double>(b.n);
      md += "| " + kind + " | " + (b.lo == b.hi ? num(b.lo) : num(b.lo) + "–" + num(b.hi)) + " | " +
            std::to_string(b.n) + " | " + std::to_string(b.detected) + " | " + num(pd) + " " +
            interval_text(d) + " | " + std::to_string(b.isolated) + " | " + num(pi) + " " + interval_text(i) +
            " |\n";
      plot.data += num(b.x) + ' ' + num(pd) + ' ' + num(d.lower) + ' ' + num(d.upper) + ' ' + num(pi) + ' ' +
                   num(i.lower) + ' ' + num(i.upper) + '\n';
    }
    plot.body = std::string(log ? "set logscale x\n" : "") +
                "set grid\nset key bottom right\nset yrange [0:1.05]\nset xlabel '|size| of the " + kind +
                " fault'\nset ylabel 'probability (95 % Clopper-Pearson)'\nset title '" + kind +
                " faults: detection and isolation against size'\n"
                "plot datafile using 1:2:3:4 with yerrorlines lw 2 pt 7 title 'detected', '' using "
                "1:5:6:7 with yerrorlines lw 2 pt 5 title 'isolated (the faulty gyro)'\n";
    report.plots.push_back(std::move(plot));
  }
  md += "\n";
  for (const auto& entry : by_kind) md += "![" + entry.first + "](" + size_plot_name(entry.first) + ")\n";
  md += "\n";
}

}  // namespace

void add_statistics(const std::vector<CampaignRow>& rows, CampaignReport& report) {
  report.markdown += "\n## Statistics with confidence\n\n" + rates_section(rows);
  size_curves(rows, report);
  report.markdown += false_alarm_section(rows);
}

}  // namespace tetra::sim
