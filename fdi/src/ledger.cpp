#include "tetra/fdi/ledger.hpp"

#include <cmath>
#include <cstdio>

#include "tetra/core/csv.hpp"
#include "tetra/core/json.hpp"

namespace tetra::fdi {

// The sources, their statistics' units and what each tests (docs/fdi.md, "The sources").
const EvidenceSourceInfo kEvidenceSources[kEvidenceSourceCount] = {
    {EvidenceSource::kChi2, "chi2", StatisticUnit::kChi2, "one epoch's parity against its noise"},
    {EvidenceSource::kCusum, "cusum", StatisticUnit::kSigma, "the parity's accumulated excess over k"},
    {EvidenceSource::kLevel, "level", StatisticUnit::kSigma, "the parity's change from an episode's level"},
    {EvidenceSource::kJump, "jump", StatisticUnit::kCount,
     "epochs in a row in which only this gyro's hypothesis explains the step within the motion bound"},
    {EvidenceSource::kOnset, "onset", StatisticUnit::kMotionBound,
     "the rate change across the onset, without the hypothesis's gyro, against the motion bound"},
    {EvidenceSource::kGlt, "glt", StatisticUnit::kChi2,
     "the mean parity since the onset (and its change from before it), less the hypothesis's gyro's fault "
     "fitted, against the noise the data show and the calibration's tolerance"},
    {EvidenceSource::kTimeout, "timeout", StatisticUnit::kSeconds, "how long the gyro has delivered nothing"},
    {EvidenceSource::kInvalid, "invalid", StatisticUnit::kSeconds,
     "how long the gyro has delivered invalid samples"},
    {EvidenceSource::kRepeated, "repeated", StatisticUnit::kCount, "identical raw values in a row"},
    {EvidenceSource::kZero, "zero", StatisticUnit::kCount, "identical raw values of 0 V in a row"},
    {EvidenceSource::kVariance, "variance", StatisticUnit::kRatio, "the gyro's robust noise level, too low"},
    {EvidenceSource::kNoiseLevel, "noise_level", StatisticUnit::kRatio,
     "the gyro's robust noise level, too high"},
    {EvidenceSource::kRecurringSpikes, "recurring_spikes", StatisticUnit::kCount,
     "confirmed one-epoch outliers of the gyro within spike_window_s"},
    {EvidenceSource::kReferenceWindow, "reference_window", StatisticUnit::kSigma,
     "the largest disagreement with the reference among the gyros the hypothesis holds healthy"},
    {EvidenceSource::kFilterBias, "filter_bias", StatisticUnit::kSigma,
     "the largest filter bias estimate among the gyros the hypothesis holds healthy"},
    {EvidenceSource::kReferenceTest, "reference_test", StatisticUnit::kChi2,
     "the reference's innovations (the failing test: jump, lag, block NIS or bias) against the gyros"},
    {EvidenceSource::kQuiet, "quiet", StatisticUnit::kSeconds, "time since the last alarm of the episode"},
    {EvidenceSource::kDriftWander, "drift_wander", StatisticUnit::kRatio,
     "the bias random walk a common drift of the gyros needs for the reference's mean innovation, over the "
     "model's own wander, at least rho times the last match's (working gyros: at most 1e4)"},
    {EvidenceSource::kMotionFit, "motion_fit", StatisticUnit::kChi2,
     "the parity's linear fit to the body rate over a block (the hypothesis's own form fitted: H0 none, "
     "Hi gyro i's alone), against the noise and the calibration's stated tolerance"},
    {EvidenceSource::kParitySpread, "parity_spread", StatisticUnit::kLogLikelihood,
     "the spread of the parity's differences between consecutive epochs, against the white noise the model "
     "states (H0: the unit's white noise as stated)"},
    {EvidenceSource::kUncheckedNoise, "unchecked_noise", StatisticUnit::kRatio,
     "the white noise variance, over the model's, that would explain an alarm, while the parity's spread has "
     "not checked the model (Hnoise consistent up to spread_held_ratio)"},
    {EvidenceSource::kParityBlockMatch, "parity_block_match", StatisticUnit::kLogLikelihood,
     "the CUSUM of the parity's block means of the filter's innovations on a gyro's column, against their "
     "variance under the model (H0: the bias model as stated)"},
    {EvidenceSource::kBiasFit, "bias_fit", StatisticUnit::kChi2,
     "how much less of an episode's parity mean and reference disagreements the hypothesis's one fault "
     "explains than the best one's (the best 0; rejected beyond bias_hypothesis_margin_sigma2); no call for "
     "every hypothesis when the best one's fit leaves more than the model accepts"},
    {EvidenceSource::kBiasPersists, "bias_persists", StatisticUnit::kChi2,
     "the best-fitting fault's χ²₁ over the latest half of the span: consistent when at least "
     "bias_hypothesis_persist_sigma2 and of the filter estimate's sign (a spike has gone by then)"},
    {EvidenceSource::kDriftShape, "drift_shape", StatisticUnit::kChi2,
     "the isolated gyro's kind: G_step − G_ramp, the parity's best step fit less its best ramp fit over the "
     "history; beyond ±drift_margin_sigma2 a bias or a ramp (consistent), else no call (unknown) unless an "
     "offset without a trend (slope's fit below drift_no_trend_sigma2) names a bias; for Hdrift, the "
     "reference's failed step test: its best step fit less the best ramp fit (3 dof), rejected above 0 (the "
     "step explains the innovations better than the ramp a common drift of the gyros makes)"},
};

bool reads_own_signal(EvidenceSource source) {
  switch (source) {
    case EvidenceSource::kTimeout:
    case EvidenceSource::kInvalid:
    case EvidenceSource::kRepeated:
    case EvidenceSource::kZero:
    case EvidenceSource::kVariance:
    case EvidenceSource::kNoiseLevel:
    case EvidenceSource::kRecurringSpikes:
      return true;
    default:
      return false;
  }
}

const char* to_string(RowVerdict verdict) {
  switch (verdict) {
    case RowVerdict::kConsistent:
      return "consistent";
    case RowVerdict::kRejected:
      return "rejected";
    case RowVerdict::kNoCall:
      return "no call";
  }
  return "no call";
}

const char* to_string(StatisticUnit unit) {
  switch (unit) {
    case StatisticUnit::kChi2:
      return "chi2";
    case StatisticUnit::kSigma:
      return "sigma";
    case StatisticUnit::kMotionBound:
      return "motion bound";
    case StatisticUnit::kSeconds:
      return "s";
    case StatisticUnit::kCount:
      return "count";
    case StatisticUnit::kRatio:
      return "ratio";
    case StatisticUnit::kLogLikelihood:
      return "log-likelihood";  // a log-likelihood ratio (15 bytes on the wire at most)
  }
  return "";
}

const EvidenceSourceInfo& info(EvidenceSource source) {
  return kEvidenceSources[static_cast<int>(source)];
}

const char* to_string(EvidenceSource source) {
  return info(source).name;
}

bool evidence_source_from_string(std::string_view text, EvidenceSource& out) {
  for (const auto& s : kEvidenceSources) {
    if (text == s.name) {
      out = s.source;
      return true;
    }
  }
  return false;
}

std::string hypothesis_name(std::uint8_t hypothesis) {
  if (hypothesis == kHypothesisReference) return "Href";
  if (hypothesis == kHypothesisDrift) return "Hdrift";
  if (hypothesis == kHypothesisCalibration) return "Hcal";
  if (hypothesis == kHypothesisNoise) return "Hnoise";
  return "H" + std::to_string(hypothesis);
}

bool hypothesis_from_string(std::string_view text, std::uint8_t& out) {
  if (text == "Href" || text == "Hdrift" || text == "Hcal" || text == "Hnoise") {
    out = text == "Href"     ? kHypothesisReference
          : text == "Hdrift" ? kHypothesisDrift
          : text == "Hcal"   ? kHypothesisCalibration
                             : kHypothesisNoise;
    return true;
  }
  if (text.size() < 2 || text.size() > 3 || text[0] != 'H') return false;
  int value = 0;
  for (char c : text.substr(1)) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + (c - '0');
  }
  if (value > 32 || (text.size() == 3 && text[1] == '0')) return false;
  out = static_cast<std::uint8_t>(value);
  return true;
}

namespace {
bool same_number(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}
}  // namespace

bool LedgerRow::operator==(const LedgerRow& other) const {
  return source == other.source && hypothesis == other.hypothesis && verdict == other.verdict &&
         dof == other.dof && same_number(statistic, other.statistic) &&
         same_number(threshold, other.threshold) && same_number(accept, other.accept);
}

LedgerRow judge(EvidenceSource source, std::uint8_t hypothesis, double statistic, double accept,
                double reject, int dof) {
  RowVerdict verdict = RowVerdict::kNoCall;
  if (statistic > reject) {
    verdict = RowVerdict::kRejected;
  } else if (statistic <= accept) {
    verdict = RowVerdict::kConsistent;
  }
  LedgerRow row = stated(source, hypothesis, verdict, statistic, reject, dof);
  row.accept = accept;
  return row;
}

LedgerRow stated(EvidenceSource source, std::uint8_t hypothesis, RowVerdict verdict, double statistic,
                 double threshold, int dof) {
  LedgerRow row;
  row.source = source;
  row.hypothesis = hypothesis;
  row.verdict = verdict;
  row.dof = static_cast<std::uint8_t>(dof);
  row.statistic = statistic;
  row.threshold = threshold;
  row.accept = threshold;
  return row;
}

namespace {
void append_number(std::string& out, double value) {
  if (std::isfinite(value)) {
    append_double(out, value);
  } else {
    out += "null";
  }
}
}  // namespace

void append_json(std::string& out, const LedgerRow& row) {
  out += "{\"source\": ";
  append_json_string(out, to_string(row.source));
  out += ", \"hypothesis\": ";
  append_json_string(out, hypothesis_name(row.hypothesis));
  out += ", \"statistic\": ";
  append_number(out, row.statistic);
  out += ", \"unit\": ";
  append_json_string(out, to_string(info(row.source).unit));
  if (info(row.source).unit == StatisticUnit::kChi2) {
    out += ", \"dof\": ";
    append_int(out, row.dof);
  }
  out += ", \"threshold\": ";
  append_number(out, row.threshold);
  if (!same_number(row.accept, row.threshold)) {
    out += ", \"accept\": ";
    append_number(out, row.accept);
  }
  out += ", \"verdict\": ";
  append_json_string(out, to_string(row.verdict));
  out += '}';
}

std::string to_text(const LedgerRow& row) {
  char text[200];
  const char* unit = to_string(info(row.source).unit);
  if (same_number(row.accept, row.threshold)) {
    std::snprintf(text, sizeof text, "%-16s %-5s %12.6g %-12s threshold %-10.6g %s", to_string(row.source),
                  hypothesis_name(row.hypothesis).c_str(), row.statistic, unit, row.threshold,
                  to_string(row.verdict));
  } else {
    std::snprintf(text, sizeof text, "%-16s %-5s %12.6g %-12s accept <= %.6g, reject > %.6g  %s",
                  to_string(row.source), hypothesis_name(row.hypothesis).c_str(), row.statistic, unit,
                  row.accept, row.threshold, to_string(row.verdict));
  }
  return text;
}

}  // namespace tetra::fdi
