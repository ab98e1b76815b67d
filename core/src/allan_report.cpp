// Reports of an Allan analysis: CSV and JSON of docs/interfaces.md §2.6, a table like seed Table 6, and the
// calibration file's noise sections.
#include <cmath>
#include <cstdio>

#include "tetra/core/allan.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/json.hpp"

namespace tetra::allan {

namespace {

std::string sci(double v, int digits = 2) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*e", digits, v);
  return buf;
}

std::string pad(std::string s, std::size_t width) {
  // Width in code points, so that "√" and "²" count as one column.
  std::size_t cols = 0;
  for (const char ch : s) cols += (static_cast<unsigned char>(ch) & 0xC0) != 0x80 ? 1 : 0;
  if (cols < width) s.append(width - cols, ' ');
  return s;
}

// Units of each term for rate data in `rate_unit` ("deg/s" or "V").
std::array<std::string, kTermCount> term_units(const std::string& rate_unit) {
  if (rate_unit == "deg/s") return {"deg", "deg/√s", "deg/s", "deg/s/√s", "deg/s²"};
  return {"V·s", "V·√s", "V", "V/√s", "V/s"};
}

constexpr std::array<const char*, kTermCount> kTermNames = {
    "quantization", "angle random walk", "bias instability", "rate random walk", "rate ramp"};

}  // namespace

double customary_factor(int term) {
  switch (term) {
    case kQ:
      return 1.0;
    case kN:
      return 60.0;
    case kB:
      return 3600.0;
    case kK:
      return 3600.0 * 60.0;
    case kR:
      return 3600.0 * 3600.0;
    default:
      return 1.0;
  }
}

std::string format_csv(const LogAllan& analysis) {
  std::string out = "gyro,tau_s,adev,adev_lo,adev_hi,n\n";
  for (const GyroAllan& g : analysis.gyros) {
    for (const AdevPoint& p : g.result.points) {
      append_int(out, g.id);
      out += ',';
      append_double(out, p.tau_s);
      out += ',';
      append_double(out, p.adev);
      out += ',';
      append_double(out, p.adev_lo);
      out += ',';
      append_double(out, p.adev_hi);
      out += ',';
      append_int(out, p.terms);
      out += '\n';
    }
    for (const double tau_s : g.result.uncomputed_tau_s) {
      append_int(out, g.id);
      out += ',';
      append_double(out, tau_s);
      out += ",nan,nan,nan,0\n";  // requested, not computable: no window of consecutive samples
    }
  }
  return out;
}

std::string format_json(const LogAllan& analysis,
                        const std::vector<std::pair<std::string, std::string>>& provenance) {
  std::string out = "{";
  if (!provenance.empty()) {
    out += "\"provenance\": {";
    for (std::size_t i = 0; i < provenance.size(); ++i) {
      if (i != 0) out += ", ";
      append_json_string(out, provenance[i].first);
      out += ": ";
      append_json_string(out, provenance[i].second);
    }
    out += "},\n ";
  }
  out += "\"units\": \"" + analysis.units + "\", \"tau0_s\": ";
  append_double(out, analysis.tau0_s);
  out += ", \"gyros\": [";
  for (std::size_t i = 0; i < analysis.gyros.size(); ++i) {
    const GyroAllan& g = analysis.gyros[i];
    out += i == 0 ? "\n  " : ",\n  ";
    out += "{\"id\": ";
    append_int(out, g.id);
    for (int k = 0; k < kTermCount; ++k) {
      out += ", \"";
      out += term_symbol(k);
      out += "\": ";
      if (const auto v = g.result.fit.reported(k)) {
        append_double(out, *v);
      } else {
        out += "null";
      }
    }
    out += ", \"samples\": ";
    append_int(out, static_cast<long long>(g.result.present_samples));
    out += ", \"absent\": ";
    append_int(out, static_cast<long long>(g.absent));
    out += ", \"invalid\": ";
    append_int(out, static_cast<long long>(g.invalid));
    out += ", \"uncomputed_tau_s\": [";
    for (std::size_t k = 0; k < g.result.uncomputed_tau_s.size(); ++k) {
      if (k != 0) out += ", ";
      append_json_number(out, g.result.uncomputed_tau_s[k]);
    }
    out += "]";
    out += "}";
  }
  out += "\n]}\n";
  return out;
}

namespace {

constexpr std::size_t kColumnWidth = 16;

double unit_factor(int /*term*/) {
  return 1.0;
}

// A header naming each term's units, then one row per gyro: the reported terms times factor(term), or NO.
void append_term_table(std::string& out, const LogAllan& analysis,
                       const std::array<std::string, kTermCount>& units, double (*factor)(int)) {
  out += pad("gyro", 6);
  for (int k = 0; k < kTermCount; ++k) {
    out += pad(std::string(term_symbol(k)) + " [" + units[static_cast<std::size_t>(k)] + "]", kColumnWidth);
  }
  out += '\n';
  for (const GyroAllan& g : analysis.gyros) {
    out += pad(std::to_string(g.id), 6);
    for (int k = 0; k < kTermCount; ++k) {
      const auto v = g.result.fit.reported(k);
      out += pad(v ? sci(*v * factor(k)) : "NO", kColumnWidth);
    }
    out += '\n';
  }
}

void append_uncomputed(std::string& out, const LogAllan& analysis) {
  for (const GyroAllan& g : analysis.gyros) {
    if (g.result.uncomputed_tau_s.empty()) continue;
    out += "gyro " + std::to_string(g.id) + ": averaging times not computable (gaps leave no window):";
    for (const double tau_s : g.result.uncomputed_tau_s) out += " " + sci(tau_s, 3);
    out += " s\n";
  }
}

// Per gyro: the data behind it and the τ range where each term dominates.
void append_dominance(std::string& out, const LogAllan& analysis) {
  out += "\nWhere each term dominates the fitted curve (tau range) and the data behind each gyro:\n";
  for (const GyroAllan& g : analysis.gyros) {
    const AllanResult& r = g.result;
    out += "gyro " + std::to_string(g.id) + ": " + std::to_string(r.present_samples) + " samples used, " +
           std::to_string(g.absent) + " absent, " + std::to_string(g.invalid) + " invalid; " +
           std::to_string(r.points.size()) + " averaging times";
    if (!r.points.empty()) {
      out += " " + sci(r.points.front().tau_s) + " .. " + sci(r.points.back().tau_s) + " s";
    }
    out += '\n';
    bool any = false;
    for (int k = 0; k < kTermCount; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      if (r.fit.dominant_from_s[kk] == 0.0) continue;
      any = true;
      out += "  " + pad(kTermNames[kk], 18) + sci(r.fit.dominant_from_s[kk]) + " .. " +
             sci(r.fit.dominant_to_s[kk]) + " s" +
             (r.fit.observed[kk] ? "" : "  (the other terms explain the data as well: NO)") + '\n';
    }
    if (!any) out += "  no term could be fitted: the data cannot tell the noise terms\n";
  }
}

}  // namespace

std::string format_table(const LogAllan& analysis) {
  std::string out;
  out += "Allan variance noise terms (IEEE Std 952-1997), units " + analysis.units +
         ", tau0 = " + sci(analysis.tau0_s, 3) + " s; NO = not observed in these data\n";
  append_term_table(out, analysis, term_units(analysis.units), unit_factor);
  append_uncomputed(out, analysis);
  if (analysis.units == "deg/s") {
    out += "\nIn customary units (bias instability B; the flat floor of the Allan deviation is 0.664 B)\n";
    append_term_table(out, analysis, {"deg", "deg/√h", "deg/h", "deg/h/√h", "deg/h²"}, customary_factor);
  } else {
    out += "\n(customary units deg/√h, deg/h, ... need rates in deg/s: give --calibration CAL.yaml)\n";
  }
  append_dominance(out, analysis);
  return out;
}

Status update_calibration_noise(Calibration& cal, const LogAllan& analysis) {
  if (analysis.units != "deg/s") {
    return bad_input({kSubjectNoiseUpdate},
                     "needs rates in deg/s: the noise terms of a volts log are not in the calibration "
                     "file's units");
  }
  for (const GyroAllan& g : analysis.gyros) {
    if (g.id < 1 || g.id > cal.gyro_count()) {
      return bad_input({kSubjectNoiseUpdate},
                       "gyro " + std::to_string(g.id) + " is not in the calibration file");
    }
    GyroNoise noise;
    const NoiseFit& f = g.result.fit;
    noise.quantization_deg = f.reported(kQ);
    noise.arw_dps_rtHz = f.reported(kN);
    noise.bias_instability_dps = f.reported(kB);
    noise.rate_random_walk_dps_per_rts = f.reported(kK);
    noise.rate_ramp_dps_per_s = f.reported(kR);
    cal.gyros[static_cast<std::size_t>(g.id - 1)].noise = noise;
  }
  return ok_status();
}

}  // namespace tetra::allan
