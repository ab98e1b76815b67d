// A campaign's rows: runs.csv's header, a row written and read back, and a row checked against the spec's
// matrix (docs/campaign.md, "Output").
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/sim/campaign.hpp"
#include "text.hpp"

namespace tetra::sim {

namespace {

//! Fields of a row (campaign_csv_header), and the index of `error` among them (columns appended after
//! it keep it where it is).
constexpr std::size_t kCampaignColumns = 25;
constexpr std::size_t kErrorColumn = 24;

std::string opt_text(const std::optional<double>& v) {
  std::string out;
  if (v) append_double(out, *v);
  return out;
}

//! NaN (not available) as an empty field.
std::string num_text(double v) {
  return opt_text(std::isnan(v) ? std::nullopt : std::optional<double>(v));
}

}  // namespace

std::string campaign_csv_header() {
  return "run,scenario,kind,gyro,onset_s,size,seed,outcome,isolated_gyro,detection_delay_s,isolation_delay_s,"
         "theory_delay_s,false_alarms,fault_free_s,final_knowledge_error_deg,final_sigma_deg,"
         "pointing_max_before_deg,pointing_rms_after_deg,pointing_max_after_deg,recover_s,bound_deg,"
         "max_wheel_momentum_fraction,wrong_gyro,wrong_at_s,error";
}

std::string campaign_csv_header(const CampaignSpec& spec) {
  std::string out = campaign_csv_header();
  for (const std::string& column : dispersion_columns(spec.dispersions, spec.max_gyro_count()))
    out += "," + column;
  return out;
}

namespace {
//! The dispersion columns' fields of a row, each after a comma (nothing without dispersions).
std::string draw_fields(const CampaignRow& r) {
  std::string out;
  for (const std::string& field : r.draws) out += "," + field;
  return out;
}
}  // namespace

std::string campaign_csv_row(const CampaignRow& r) {
  std::string out = std::to_string(r.run) + "," + metadata_token(r.scenario) + "," + r.kind + "," +
                    std::to_string(r.gyro) + ",";
  append_double(out, r.onset_s);
  out += ',';
  append_double(out, r.size);
  out += "," + std::to_string(r.seed) + ",";
  // An error row: outcome `error`, the result columns empty, the message in `error` (column kErrorColumn).
  if (!r.error.empty()) return out + "error" + std::string(kErrorColumn - 7, ',') + r.error + draw_fields(r);
  out += std::string(outcome_name(r.fdi.outcome)) + ",";
  out += r.fdi.isolated_gyro ? std::to_string(*r.fdi.isolated_gyro) : std::string();
  out += "," + opt_text(r.fdi.detection_delay_s) + "," + opt_text(r.fdi.isolation_delay_s) + "," +
         opt_text(r.theory_delay_s) + "," + std::to_string(r.fdi.false_alarms) + ",";
  for (double v : {r.fdi.fault_free_s, r.final_knowledge_error_deg, r.final_sigma_deg,
                   r.pointing_max_before_deg, r.pointing_rms_after_deg, r.pointing_max_after_deg}) {
    out += num_text(v) + ",";
  }
  out += opt_text(r.recover_s) + "," + num_text(r.bound_deg) + "," + num_text(r.max_wheel_momentum_fraction) +
         ",";
  out += r.fdi.wrong_gyro ? std::to_string(*r.fdi.wrong_gyro) : std::string();
  out += "," + opt_text(r.fdi.wrong_at_s) + ",";
  return out + draw_fields(r);
  return out;
}

Result<CampaignRow> parse_campaign_row(const std::string& line, const std::string& header) {
  const auto fields = std::count(line.begin(), line.end(), ',');
  if (fields != std::count(header.begin(), header.end(), ','))
    return bad_input("campaign row with " + std::to_string(fields + 1) + " fields (the header has " +
                     std::to_string(std::count(header.begin(), header.end(), ',') + 1) + ")");
  return parse_campaign_row(line);
}

namespace {

//! The fields of one runs.csv row, each read as campaign_csv_row writes it: whole numbers in digits, other
//! numbers finite decimal text within their column's range. The first field out of its range is kept
//! (`bad`): a forged or damaged row is refused, never counted.
class RowFields {
 public:
  explicit RowFields(std::vector<std::string> fields) : f_(std::move(fields)) {
    std::stringstream header(campaign_csv_header());
    for (std::string name; std::getline(header, name, ',');) names_.push_back(name);
  }
  const std::string& text(std::size_t i) const { return f_[i]; }
  const std::string& bad() const { return bad_; }

  std::uint64_t whole(std::size_t i, std::uint64_t max, const char* range) {
    const std::string& t = f_[i];
    if (!t.empty() && t.size() <= 20 && t.find_first_not_of("0123456789") == std::string::npos) {
      try {
        const std::uint64_t v = std::stoull(t);
        if (v <= max) return v;
      } catch (const std::exception&) {
      }
    }
    refuse(i, range);
    return 0;
  }
  double num(std::size_t i, double lo) {
    if (f_[i].empty()) return std::numeric_limits<double>::quiet_NaN();
    const auto v = parse_decimal(f_[i]);
    if (v && *v >= lo) return *v;
    refuse(i, lo == 0.0 ? "a finite number >= 0" : "a finite number");
    return std::numeric_limits<double>::quiet_NaN();
  }
  std::optional<double> opt(std::size_t i) {
    return f_[i].empty() ? std::nullopt : std::optional<double>(num(i, 0.0));
  }
  std::optional<int> gyro_id(std::size_t i) {
    return f_[i].empty() ? std::nullopt
                         : std::optional<int>(static_cast<int>(whole(i, kMaxGyros, "a gyro 1..32")));
  }

 private:
  void refuse(std::size_t i, const char* range) {
    if (bad_.empty()) bad_ = names_[i] + " '" + one_line(f_[i].substr(0, 40)) + "' (" + range + ")";
  }
  std::vector<std::string> f_;
  std::vector<std::string> names_;
  std::string bad_;
};

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream in(line);
  for (std::string field; std::getline(in, field, ',');) f.push_back(field);
  if (!line.empty() && line.back() == ',') f.emplace_back();
  return f;
}

//! The run's case: run, scenario, kind, gyro, onset, size, seed and the dispersion draws.
void read_case(RowFields& f, std::size_t columns, const std::vector<std::string>& all, CampaignRow& r) {
  r.run = f.whole(0, kMaxCampaignRuns, "a run number");
  r.scenario = f.text(1);
  r.kind = f.text(2);
  r.gyro = static_cast<int>(f.whole(3, kMaxGyros, "a gyro 0..32"));
  r.onset_s = f.num(4, 0.0);
  r.size = f.num(5, -std::numeric_limits<double>::max());
  r.seed = f.whole(6, std::numeric_limits<std::uint64_t>::max(), "a seed");
  r.draws.assign(all.begin() + static_cast<std::ptrdiff_t>(columns), all.end());
}

std::optional<Outcome> outcome_from(const std::string& text) {
  for (Outcome o : {Outcome::kNone, Outcome::kRight, Outcome::kWrong, Outcome::kUnisolated, Outcome::kMissed})
    if (outcome_name(o) == text) return o;
  return std::nullopt;
}

//! The run's result: the FDI's figures, the attitude's and the pointing's.
void read_result(RowFields& f, CampaignRow& r) {
  r.fdi.isolated_gyro = f.gyro_id(8);
  r.fdi.detection_delay_s = f.opt(9);
  r.fdi.isolation_delay_s = f.opt(10);
  r.theory_delay_s = f.opt(11);
  r.fdi.false_alarms = static_cast<int>(f.whole(12, 1'000'000'000, "a count >= 0"));
  r.fdi.fault_free_s = f.num(13, 0.0);
  r.final_knowledge_error_deg = f.num(14, 0.0);
  r.final_sigma_deg = f.num(15, 0.0);
  r.pointing_max_before_deg = f.num(16, 0.0);
  r.pointing_rms_after_deg = f.num(17, 0.0);
  r.pointing_max_after_deg = f.num(18, 0.0);
  r.recover_s = f.opt(19);
  r.bound_deg = f.num(20, 0.0);
  r.max_wheel_momentum_fraction = f.num(21, 0.0);
  r.fdi.wrong_gyro = f.gyro_id(22);
  r.fdi.wrong_at_s = f.opt(23);
}

}  // namespace

Result<CampaignRow> parse_campaign_row(const std::string& line) {
  std::vector<std::string> all = split_fields(line);
  if (all.size() < kCampaignColumns)
    return bad_input("campaign row with " + std::to_string(all.size()) + " fields (" +
                     std::to_string(kCampaignColumns) + " or more expected)");
  RowFields f(all);
  CampaignRow r;
  read_case(f, kCampaignColumns, all, r);
  const std::string& outcome = f.text(7);
  const std::string& error = f.text(kErrorColumn);
  if (outcome == "error") {
    if (error.empty()) return bad_input("campaign row: outcome error without its message");
    r.error = error;
  } else {
    if (!error.empty()) return bad_input("campaign row: an error message with outcome '" + outcome + "'");
    const auto o = outcome_from(outcome);
    if (!o) return bad_input("campaign row: unknown outcome '" + one_line(outcome.substr(0, 40)) + "'");
    r.fdi.outcome = *o;
    read_result(f, r);
  }
  if (!f.bad().empty()) return bad_input("campaign row: " + f.bad());
  return r;
}

namespace {

//! Whether `a` is at most `b`, `slack` allowed (a sample period: times are the epochs').
bool within(double a, double b, double slack) {
  return a <= b + slack + 1e-9 * std::max(1.0, std::abs(b));
}

//! The case columns of `row` against the spec's case of the same run (`want`): the first that differs.
std::string case_mismatch(const CampaignRow& row, const CampaignRow& want) {
  const std::string run = "run " + std::to_string(row.run) + " of the spec's matrix has ";
  if (row.scenario != metadata_token(want.scenario))
    return "scenario '" + one_line(row.scenario.substr(0, 40)) + "' (" + run + metadata_token(want.scenario) +
           ")";
  if (row.kind != want.kind)
    return "kind '" + one_line(row.kind.substr(0, 40)) + "' (" + run + want.kind + ")";
  if (row.gyro != want.gyro)
    return "gyro '" + std::to_string(row.gyro) + "' (" + run + "gyro " + std::to_string(want.gyro) + ")";
  if (row.onset_s != want.onset_s)
    return "onset_s '" + number_text(row.onset_s) + "' (" + run + "onset " + number_text(want.onset_s) + ")";
  if (row.size != want.size)
    return "size '" + number_text(row.size) + "' (" + run + "size " + number_text(want.size) + ")";
  if (row.seed != want.seed)
    return "seed '" + std::to_string(row.seed) + "' (" + run + "seed " + std::to_string(want.seed) + ")";
  if (row.draws != want.draws)
    return "the dispersion columns (not the draws of run " + std::to_string(row.run) + ")";
  return {};
}

//! The FDI columns against the verdict's rules (judge_fdi) for a run of a fault on `gyro` (0: none) of a
//! unit of `n` gyros: the first that breaks one.
std::string verdict_mismatch(const CampaignRow& row, int n) {
  const FdiVerdict& v = row.fdi;
  const std::string outcome = "outcome '" + std::string(outcome_name(v.outcome)) + "' ";
  const auto gyro_text = [](const std::optional<int>& g) { return g ? std::to_string(*g) : std::string(); };
  for (const auto& [name, g] :
       {std::pair{"isolated_gyro", v.isolated_gyro}, std::pair{"wrong_gyro", v.wrong_gyro}}) {
    if (g && (*g < 1 || *g > n))
      return std::string(name) + " '" + gyro_text(g) + "' (a gyro 1.." + std::to_string(n) +
             " of the scenario's unit)";
  }
  if (v.isolated_gyro.has_value() != v.isolation_delay_s.has_value())
    return "isolation_delay_s (given with isolated_gyro, and only with it)";
  if (v.wrong_gyro.has_value() != v.wrong_at_s.has_value())
    return "wrong_at_s (given with wrong_gyro, and only with it)";
  if (row.gyro != 0 && v.wrong_gyro == row.gyro)
    return "wrong_gyro '" + gyro_text(v.wrong_gyro) + "' (the faulty gyro)";
  if ((v.outcome == Outcome::kWrong) != v.wrong_gyro.has_value())
    return outcome + "with wrong_gyro '" + gyro_text(v.wrong_gyro) + "'";
  if (row.kind == "none")
    return v.outcome == Outcome::kNone || v.outcome == Outcome::kWrong
               ? ""
               : outcome + "(a run without a fault is none or wrong)";
  if (v.outcome == Outcome::kNone)
    return outcome + "(a run with a fault is right, wrong, unisolated or missed)";
  if (v.outcome == Outcome::kRight && v.isolated_gyro != row.gyro)
    return outcome + "with isolated_gyro '" + gyro_text(v.isolated_gyro) + "' (the faulty gyro is " +
           std::to_string(row.gyro) + ")";
  if (v.outcome == Outcome::kUnisolated && (!v.detection_delay_s || v.isolated_gyro))
    return outcome + "(detected, never isolated: a detection_delay_s and no isolated_gyro)";
  if (v.outcome == Outcome::kMissed && (v.detection_delay_s || v.isolated_gyro))
    return outcome + "(neither detected nor isolated: no detection_delay_s and no isolated_gyro)";
  return {};
}

//! The times of a finished run within it (`slack`: one sample period): the time before the onset (the
//! whole run without a fault; the onset as drawn with a dispersed one), the delays after it, the rest.
std::string time_mismatch(const CampaignRow& row, double duration_s, double slack) {
  const FdiVerdict& v = row.fdi;
  const std::string end = "the run's end at " + number_text(duration_s) + " s)";
  const double onset = v.fault_free_s;
  if (!within(onset, duration_s, slack) || (row.kind == "none" && !within(duration_s, onset, slack)))
    return "fault_free_s '" + number_text(onset) + "' (" +
           (row.kind == "none" ? "a run without a fault is fault-free to " : "beyond ") + end;
  for (const auto& [name, delay] : {std::pair{"detection_delay_s", v.detection_delay_s},
                                    std::pair{"isolation_delay_s", v.isolation_delay_s}}) {
    if (delay && !within(onset + *delay, duration_s, slack))
      return std::string(name) + " '" + number_text(*delay) + "' (after the onset at " + number_text(onset) +
             " s: beyond " + end;
  }
  if (v.wrong_at_s && !within(*v.wrong_at_s, duration_s, slack))
    return "wrong_at_s '" + number_text(*v.wrong_at_s) + "' (beyond " + end;
  if (row.recover_s && !within(*row.recover_s, duration_s, slack))
    return "recover_s '" + number_text(*row.recover_s) + "' (beyond " + end;
  return {};
}

//! The columns a run's loop and kind give: theory_delay_s for bias faults only, no pointing in open loop.
std::string column_mismatch(const CampaignSpec& spec, const CampaignRow& row) {
  if (row.theory_delay_s && row.kind != fault_kind_name(FaultKind::kBias))
    return "theory_delay_s '" + number_text(*row.theory_delay_s) + "' (for bias faults only)";
  if (spec.loop != CampaignLoop::kOpen) return {};
  for (const auto& [name, value] : {std::pair{"pointing_max_before_deg", row.pointing_max_before_deg},
                                    std::pair{"pointing_rms_after_deg", row.pointing_rms_after_deg},
                                    std::pair{"pointing_max_after_deg", row.pointing_max_after_deg},
                                    std::pair{"bound_deg", row.bound_deg}}) {
    if (!std::isnan(value))
      return std::string(name) + " '" + number_text(value) + "' (an open-loop run has no pointing)";
  }
  if (row.recover_s) return "recover_s (an open-loop run has no pointing)";
  return {};
}

}  // namespace

Status check_campaign_row(const CampaignSpec& spec, const CampaignRow& row) {
  auto runs = campaign_run_count(spec);
  if (!runs) return runs.error();
  if (row.run >= *runs)
    return bad_input("campaign row: run '" + std::to_string(row.run) + "' (the campaign has runs 0 to " +
                     std::to_string(*runs - 1) + ")");
  std::string bad = case_mismatch(row, campaign_error_row(spec, row.run, "-"));
  if (bad.empty() && row.error.empty()) {
    // The unit, rate and length the run had (dispersions change neither).
    const Scenario& sc = spec.scenarios[campaign_case(spec, row.run).scenario];
    bad = verdict_mismatch(row, sc.unit.gyro_count());
    if (bad.empty()) bad = time_mismatch(row, spec.duration_s.value_or(sc.duration_s), 1.0 / sc.rate_hz);
    if (bad.empty()) bad = column_mismatch(spec, row);
  }
  if (!bad.empty()) return bad_input("campaign row: " + bad);
  return ok_status();
}

}  // namespace tetra::sim
