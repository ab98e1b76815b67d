#pragma once
// The hypothesis ledger (docs/fdi.md, "The ledger and the arbiter"): every evidence source writes, per
// hypothesis, one typed row — H0 (no fault), H1…HN (gyro i faulty, every other healthy), Href (the attitude
// reference is wrong) — with its statistic, the statistic's unit, the threshold and the verdict; decision
// events carry the rows that decided them. One table lists the sources (`kEvidenceSources`), one helper fills
// a row (`judge`), one rule reads them (arbiter.hpp).

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

namespace tetra::fdi {

//! What a row says of its hypothesis: the data are consistent with it, reject it, or cannot tell.
enum class RowVerdict : std::uint8_t { kConsistent, kRejected, kNoCall };
const char* to_string(RowVerdict verdict);  // "consistent", "rejected", "no call"

//! Every source of evidence, in the order of kEvidenceSources.
enum class EvidenceSource : std::uint8_t {
  kChi2,              //!< parity χ² of one epoch
  kCusum,             //!< parity CUSUM
  kLevel,             //!< CUSUM on the parity minus an open episode's held level
  kJump,              //!< one-epoch jump test, confirmed over onset_confirm_epochs
  kOnset,             //!< window means before and after the onset against the motion bound
  kGlt,               //!< generalized likelihood test on the mean parity since the onset (N ≥ 5)
  kTimeout,           //!< a gyro absent for dropout_timeout_s
  kInvalid,           //!< a gyro invalid for dropout_timeout_s
  kRepeated,          //!< identical raw values in a row (stuck)
  kZero,              //!< identical raw values, all 0 V
  kVariance,          //!< robust noise level too low
  kNoiseLevel,        //!< robust noise level too high
  kRecurringSpikes,   //!< confirmed one-epoch outliers, noise otherwise normal
  kReferenceWindow,   //!< each gyro's angle against the reference's over a window
  kFilterBias,        //!< the attitude filter's bias estimates (reference and parity)
  kReferenceTest,     //!< the reference's own consistency tests (NIS, lag, bias, jump)
  kQuiet,             //!< no alarm for clear_after_s: the episode's fault is gone
  kDriftWander,       //!< the bias wander a common drift of the gyros would need, against a working unit's
  kMotionFit,         //!< the parity's fit to the body rate over a block: scale factors and axes
  kParitySpread,      //!< the parity's differences between consecutive epochs: the unit's white noise
  kUncheckedNoise,    //!< the white noise an alarm needs, while the spread has not checked the model
  kParityBlockMatch,  //!< the parity's block means of the filter's innovations: each gyro's bias model
  kBiasFit,           //!< one gyro's fault fitted to an episode's parity mean and reference disagreements
  kBiasPersists,      //!< the best-fitting fault in the latest half of that span, of the filter's sign
  kDriftShape  //!< a step or a ramp: the isolated gyro's kind (it decides no exclusion); a reference's step
               //!< against the gyros' common drift (Hdrift)
};
constexpr int kEvidenceSourceCount = 25;
//! True for the sources that read a gyro's own signal (timeout, invalid, repeated, zero, variance,
//! noise_level, recurring_spikes): no error of the calibration makes what they see.
bool reads_own_signal(EvidenceSource source);

//! The unit of a source's statistic (one meaning per source, stated in its table row).
enum class StatisticUnit : std::uint8_t {
  kChi2,         //!< χ² with `dof` degrees of freedom
  kSigma,        //!< multiples of the statistic's own σ
  kMotionBound,  //!< ratio of a rate change to the motion bound (a_max·Δt + onset_sigma·σ): > 1 impossible
  kSeconds,      //!< [s]
  kCount,        //!< a number of samples or events
  kRatio,        //!< a noise level over the model's
  kLogLikelihood  //!< a log-likelihood ratio
};
const char* to_string(
    StatisticUnit unit);  // "chi2", "sigma", "motion bound", "s", "count", "ratio", "log-likelihood"

//! One row of the source table: its name in events, its statistic's unit and what it tests.
struct EvidenceSourceInfo {
  EvidenceSource source;
  const char* name;
  StatisticUnit unit;
  const char* tests;
};
extern const EvidenceSourceInfo kEvidenceSources[kEvidenceSourceCount];
const EvidenceSourceInfo& info(EvidenceSource source);
const char* to_string(EvidenceSource source);
//! The source named by `text` (as written by to_string), if any.
bool evidence_source_from_string(std::string_view text, EvidenceSource& out);

//! Hypotheses: 0 is H0, 1..N gyro i, kHypothesisReference the reference, kHypothesisDrift the gyros' common
//! bias drifting beyond their noise model (every gyro's bias together: the parity cannot see it),
//! kHypothesisCalibration the calibration's scale factors and axes not describing the unit (several gyros
//! at once, beyond their stated tolerance), kHypothesisNoise every gyro's white noise beyond the model, up to
//! what a model the parity's spread has not checked yet may hide (design::spread_held_ratio).
inline constexpr std::uint8_t kHypothesisNone = 0;
inline constexpr std::uint8_t kHypothesisNoise = 252;
inline constexpr std::uint8_t kHypothesisCalibration = 253;
inline constexpr std::uint8_t kHypothesisDrift = 254;
inline constexpr std::uint8_t kHypothesisReference = 255;
//! "H0", "H3", "Hnoise", "Hcal", "Hdrift", "Href".
std::string hypothesis_name(std::uint8_t hypothesis);
//! The hypothesis named by `text` ("H0", "H1".."H32", "Hnoise", "Hcal", "Hdrift", "Href"), if any.
bool hypothesis_from_string(std::string_view text, std::uint8_t& out);

//! One ledger row: `source`'s verdict on `hypothesis`. The statistic is compared with `threshold`: above it
//! the hypothesis is rejected; at or below `accept` it is consistent; between the two, no call.
struct LedgerRow {
  EvidenceSource source = EvidenceSource::kChi2;
  std::uint8_t hypothesis = kHypothesisNone;
  RowVerdict verdict = RowVerdict::kNoCall;
  std::uint8_t dof = 0;  //!< degrees of freedom of a χ² statistic (0 otherwise)
  double statistic = std::numeric_limits<double>::quiet_NaN();
  double threshold = std::numeric_limits<double>::quiet_NaN();  //!< rejected above it
  double accept = std::numeric_limits<double>::quiet_NaN();     //!< consistent at or below it (≤ threshold)
  bool operator==(const LedgerRow& other) const;
};

//! The one helper that fills a row: rejected when `statistic > reject`, consistent when `statistic <=
//! accept` (accept ≤ reject), else no call; a statistic that is not a number makes no call.
LedgerRow judge(EvidenceSource source, std::uint8_t hypothesis, double statistic, double accept,
                double reject, int dof = 0);
//! A row whose verdict the source states directly (a signature's own-signal test: the hypothesis that its
//! gyro is healthy is rejected by the same statistic that names it).
LedgerRow stated(EvidenceSource source, std::uint8_t hypothesis, RowVerdict verdict, double statistic,
                 double threshold, int dof = 0);

//! The single rule (docs/fdi.md, "The arbiter"): gyro i is excluded when Hi is consistent — some row says so
//! and none rejects it — and every other single-gyro hypothesis of `active` is rejected by some row, H0 too,
//! Href too when a reference exists (`reference_exists`), and Hcal does not stand (a row writes it only
//! while a calibration mismatch stands). Returns i, or 0 when no hypothesis stands alone.
int arbitrate(const LedgerRow* begin, const LedgerRow* end, std::uint32_t active, bool reference_exists);

//! The same rule for an alarm: it decides (a detection, an episode opened) when H0 is rejected and Hnoise
//! does not stand (a row writes it only while the noise model is unchecked).
bool arbitrate_detection(const LedgerRow* begin, const LedgerRow* end);

//! What the arbiter makes of a reference sample's rows.
enum class ReferenceDecision : std::uint8_t {
  kUse,         //!< H0 stands: the sample is used
  kReject,      //!< Href stands alone: the reference is left out
  kMatchDrift,  //!< Hdrift stands (Href may too): the gyros' bias model opened, the reference kept
  kNoCall       //!< a gyro's hypothesis or Hcal stands beside Href: reported, nothing else changes
};
const char* to_string(ReferenceDecision decision);  // "use", "reject", "match drift", "no call"

//! The same rule for the reference (docs/fdi.md, "The arbiter"): H0 not rejected — the sample is used;
//! else, unless every single-gyro hypothesis of `active` is rejected, no call; else a consistent Hdrift is
//! matched (the cheaper step: it opens a model and keeps the reference, and a mean that persists after it
//! rejects Hdrift); else no call while Hcal stands (the gyros' calibration explains the disagreement as
//! well); else Href consistent with Hdrift rejected rejects the reference.
ReferenceDecision arbitrate_reference(const LedgerRow* begin, const LedgerRow* end, std::uint32_t active);

//! The same rule for a block of the motion fit: true when Hcal stands alone — H0 and every single-gyro
//! hypothesis of `active` rejected, Hcal consistent.
bool arbitrate_calibration(const LedgerRow* begin, const LedgerRow* end, std::uint32_t active);

//! `{"source": …, "hypothesis": …, "statistic": …, "unit": …, "dof": …, "threshold": …, "accept": …,
//! "verdict": …}` appended (dof only for χ², accept only where it differs from the threshold).
void append_json(std::string& out, const LedgerRow& row);
//! One line per row for a terminal: "onset       H2    0.41 motion bound <= 1  consistent".
std::string to_text(const LedgerRow& row);

}  // namespace tetra::fdi
