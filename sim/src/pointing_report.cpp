#include "tetra/sim/pointing_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/json.hpp"

namespace tetra::sim {

namespace {

PointingSegment segment_of(const std::vector<PointingSample>& series, double from_s, double to_s,
                           double bound_deg, double dt_s) {
  PointingSegment seg;
  seg.from_s = from_s;
  seg.to_s = to_s;
  double sum2 = 0.0;
  double est_sum2 = 0.0;
  std::size_t count = 0;
  std::size_t est_count = 0;
  std::optional<double> last_above_s;
  bool ends_above = false;
  for (const PointingSample& s : series) {
    if (s.time_s < from_s || s.time_s >= to_s) continue;
    sum2 += s.error_deg * s.error_deg;
    ++count;
    if (std::isfinite(s.estimated_error_deg)) {
      est_sum2 += s.estimated_error_deg * s.estimated_error_deg;
      ++est_count;
    }
    seg.max_deg = std::max(seg.max_deg, s.error_deg);
    ends_above = s.error_deg > bound_deg;
    if (ends_above) last_above_s = s.time_s;
  }
  seg.rms_deg = count ? std::sqrt(sum2 / static_cast<double>(count)) : 0.0;
  seg.estimated_rms_deg = est_count ? std::sqrt(est_sum2 / static_cast<double>(est_count)) : 0.0;
  if (!last_above_s) {
    seg.recover_s = 0.0;
  } else if (!ends_above) {
    seg.recover_s = *last_above_s + dt_s - from_s;
  }
  return seg;
}

void add_number(std::string& out, const char* key, double value, bool comma = true) {
  out += "  \"";
  out += key;
  out += "\": ";
  append_json_number(out, value);
  if (comma) out += ',';
  out += '\n';
}

void add_optional(std::string& out, const char* key, const std::optional<double>& value) {
  if (value) {
    append_json_number(out += std::string("\"") + key + "\": ", *value);
  } else {
    out += std::string("\"") + key + "\": null";
  }
}

}  // namespace

PointingSummary summarize(const ClosedLoopRecord& record, const ClosedLoopSimulator& simulator) {
  PointingSummary s;
  const ClosedLoopSpec& spec = simulator.spec();
  const double duration_s = simulator.scenario().duration_s;
  const double dt_s = 1.0 / simulator.scenario().rate_hz;
  s.bound_deg = spec.pointing_bound_deg;
  std::set<double> onsets;
  for (const FaultSpec& f : simulator.faults()) {
    if (f.at_s < duration_s) onsets.insert(f.at_s);
  }
  std::vector<double> edges = {0.0};
  edges.insert(edges.end(), onsets.begin(), onsets.end());
  edges.push_back(INFINITY);
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    if (edges[i + 1] <= edges[i]) continue;
    PointingSegment seg = segment_of(record.series, edges[i], edges[i + 1], s.bound_deg, dt_s);
    seg.to_s = std::min(seg.to_s, duration_s);
    if (i == 0) {
      seg.label = "before faults";
    } else {
      for (const FaultSpec& f : simulator.faults()) {
        if (f.at_s != edges[i]) continue;
        if (!seg.label.empty()) seg.label += "; ";
        seg.label += format_fault_spec(f);
      }
    }
    if (!seg.recover_s) s.within_bound_after_recovery = false;  // every segment, the first too
    s.segments.push_back(seg);
  }
  const PointingSegment all = segment_of(record.series, 0.0, INFINITY, s.bound_deg, dt_s);
  s.rms_deg = all.rms_deg;
  s.max_deg = all.max_deg;
  if (!record.series.empty()) {
    const PointingSample& last = record.series.back();
    s.final_error_deg = last.error_deg;
    s.final_knowledge_error_deg = last.knowledge_error_deg;
    s.final_sigma_deg = last.sigma_deg;
  }
  double age_sum_s = 0.0;
  std::size_t ages = 0;
  for (const PointingSample& p : record.series) {
    if (p.torque_limited) s.torque_limited_s += dt_s;
    if (p.momentum_limited) s.momentum_limited_s += dt_s;
    if (std::isfinite(p.estimate_age_s)) {
      age_sum_s += p.estimate_age_s;
      ++ages;
      s.max_estimate_age_s = std::max(s.max_estimate_age_s, p.estimate_age_s);
    }
  }
  if (ages > 0) s.mean_estimate_age_s = age_sum_s / static_cast<double>(ages);
  s.max_wheel_momentum_fraction = record.max_wheel_momentum_fraction;
  s.counters = record.counters;
  s.fdi = judge_fdi(record.events, simulator.faults(), duration_s);
  return s;
}

std::string summary_json(const PointingSummary& s, bool with_fdi) {
  std::string out = "{\n";
  add_number(out, "pointing_bound_deg", s.bound_deg);
  add_number(out, "rms_deg", s.rms_deg);
  add_number(out, "max_deg", s.max_deg);
  add_number(out, "final_error_deg", s.final_error_deg);
  add_number(out, "final_knowledge_error_deg", s.final_knowledge_error_deg);
  add_number(out, "final_sigma_deg", s.final_sigma_deg);
  out += "  \"recovered\": ";
  out += s.within_bound_after_recovery ? "true,\n" : "false,\n";
  out += "  \"segments\": [";
  for (std::size_t i = 0; i < s.segments.size(); ++i) {
    const PointingSegment& g = s.segments[i];
    out += i ? ",\n    {" : "\n    {";
    out += "\"label\": ";
    append_json_string(out, g.label);
    append_json_number(out += ", \"from_s\": ", g.from_s);
    append_json_number(out += ", \"to_s\": ", g.to_s);
    append_json_number(out += ", \"rms_deg\": ", g.rms_deg);
    append_json_number(out += ", \"max_deg\": ", g.max_deg);
    append_json_number(out += ", \"estimated_rms_deg\": ", g.estimated_rms_deg);
    out += ", ";
    add_optional(out, "recover_s", g.recover_s);
    out += '}';
  }
  out += "\n  ],\n  \"wheels\": {";
  append_json_number(out += "\"max_momentum_fraction\": ", s.max_wheel_momentum_fraction);
  append_json_number(out += ", \"torque_limited_s\": ", s.torque_limited_s);
  append_json_number(out += ", \"momentum_limited_s\": ", s.momentum_limited_s);
  out += "},\n  \"control\": {";
  append_json_number(out += "\"normal_epochs\": ", static_cast<double>(s.counters.normal_epochs));
  append_json_number(out += ", \"hold_epochs\": ", static_cast<double>(s.counters.hold_epochs));
  append_json_number(out += ", \"safe_epochs\": ", static_cast<double>(s.counters.safe_epochs));
  append_json_number(out += ", \"safe_entries\": ", static_cast<double>(s.counters.safe_entries));
  append_json_number(out += ", \"lost_epochs\": ", static_cast<double>(s.counters.lost_epochs));
  append_json_number(out += ", \"mean_estimate_age_s\": ", s.mean_estimate_age_s);
  append_json_number(out += ", \"max_estimate_age_s\": ", s.max_estimate_age_s);
  out += "},\n  \"fdi\": ";
  if (!with_fdi) return out + "null\n}\n";
  out += "{\"outcome\": ";
  append_json_string(out, outcome_name(s.fdi.outcome));
  out += ", ";
  add_optional(out, "detection_delay_s", s.fdi.detection_delay_s);
  out += ", ";
  add_optional(out, "isolation_delay_s", s.fdi.isolation_delay_s);
  out += ", ";
  add_optional(out, "isolated_gyro",
               s.fdi.isolated_gyro ? std::optional<double>(*s.fdi.isolated_gyro) : std::nullopt);
  append_json_number(out += ", \"false_alarms\": ", s.fdi.false_alarms);
  out += "}\n}\n";
  return out;
}

Status write_pointing_csv(const std::string& path, const ClosedLoopRecord& record, int n_gyros) {
  std::string text =
      "time_s,error_deg,estimated_error_deg,knowledge_error_deg,sigma_deg,age_s,mode,gyros,control";
  const Eigen::Index wheels = record.series.empty() ? 0 : record.series.front().wheel_speed_rpm.size();
  for (Eigen::Index i = 1; i <= wheels; ++i) text += ",speed_rpm_" + std::to_string(i);
  for (Eigen::Index i = 1; i <= wheels; ++i) text += ",torque_Nm_" + std::to_string(i);
  text += '\n';
  for (const PointingSample& s : record.series) {
    append_double(text, s.time_s);
    for (double v :
         {s.error_deg, s.estimated_error_deg, s.knowledge_error_deg, s.sigma_deg, s.estimate_age_s}) {
      text += ',';
      if (std::isfinite(v)) append_double(text, v);
    }
    text += ',';
    text += fdi::to_string(s.mode);
    text += ',';
    text += mask_to_string(s.gyros, n_gyros);
    text += ',';
    text += to_string(s.control);
    for (Eigen::Index i = 0; i < wheels; ++i) append_double(text += ',', s.wheel_speed_rpm[i] + 0.0);
    for (Eigen::Index i = 0; i < wheels; ++i) append_double(text += ',', s.wheel_torque_Nm[i] + 0.0);
    text += '\n';
  }
  return write_text_file(path, text);
}

}  // namespace tetra::sim
