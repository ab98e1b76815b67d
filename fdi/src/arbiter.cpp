#include "evidence_rows.hpp"

namespace tetra::fdi::detail {

void EvidenceRows::own_signal(EvidenceSource source, int culprit, GyroMask active, double statistic,
                              double threshold) {
  for (int j = 1; j <= kMaxGyros; ++j) {
    if (!has_gyro(active, j) && j != culprit) continue;
    add(stated(source, static_cast<std::uint8_t>(j),
               j == culprit ? RowVerdict::kConsistent : RowVerdict::kRejected, statistic, threshold));
  }
  add(stated(source, kHypothesisNone, RowVerdict::kRejected, statistic, threshold));
  add(stated(source, kHypothesisReference, RowVerdict::kRejected, statistic, threshold));
}

void EvidenceRows::detection(EvidenceSource source, double statistic, double threshold, int dof) {
  add(judge(source, kHypothesisNone, statistic, threshold, threshold, dof));
  add(judge(source, kHypothesisReference, statistic, threshold, threshold, dof));
}

}  // namespace tetra::fdi::detail

namespace tetra::fdi {

namespace {

//! Per hypothesis: whether any row rejected it, whether any row found it consistent.
struct Tally {
  static constexpr int kReference = kMaxGyros + 1;
  static constexpr int kDrift = kMaxGyros + 2;
  static constexpr int kCalibration = kMaxGyros + 3;
  static constexpr int kNoise = kMaxGyros + 4;
  std::array<bool, kMaxGyros + 5> rejected{};
  std::array<bool, kMaxGyros + 5> consistent{};

  Tally(const LedgerRow* begin, const LedgerRow* end) {
    for (const LedgerRow* row = begin; row != end; ++row) {
      const int s = slot(row->hypothesis);
      if (s < 0) continue;
      rejected[static_cast<std::size_t>(s)] |= row->verdict == RowVerdict::kRejected;
      consistent[static_cast<std::size_t>(s)] |= row->verdict == RowVerdict::kConsistent;
    }
  }
  static int slot(std::uint8_t h) {
    if (h == kHypothesisReference) return kReference;
    if (h == kHypothesisDrift) return kDrift;
    if (h == kHypothesisCalibration) return kCalibration;
    if (h == kHypothesisNoise) return kNoise;
    return h <= kMaxGyros ? static_cast<int>(h) : -1;
  }
  bool is_rejected(int s) const { return rejected[static_cast<std::size_t>(s)]; }
  //! Consistent: some row says so and none rejects it.
  bool stands(int s) const { return consistent[static_cast<std::size_t>(s)] && !is_rejected(s); }
  bool every_gyro_rejected(std::uint32_t active) const {
    for (int j = 1; j <= kMaxGyros; ++j)
      if (has_gyro(active, j) && !is_rejected(j)) return false;
    return true;
  }
};

}  // namespace

int arbitrate(const LedgerRow* begin, const LedgerRow* end, std::uint32_t active, bool reference_exists) {
  const Tally t(begin, end);
  if (!t.is_rejected(0)) return 0;  // no fault shown
  if (reference_exists && !t.is_rejected(Tally::kReference)) return 0;
  if (t.stands(Tally::kCalibration)) return 0;  // the calibration's error explains the parity
  int standing = 0;
  for (int j = 1; j <= kMaxGyros; ++j) {
    if (!has_gyro(active, j) || t.is_rejected(j)) continue;
    if (!t.consistent[static_cast<std::size_t>(j)] || standing != 0) return 0;  // no call, or a second one
    standing = j;
  }
  return standing;
}

bool arbitrate_detection(const LedgerRow* begin, const LedgerRow* end) {
  const Tally t(begin, end);
  return t.is_rejected(0) && !t.stands(Tally::kNoise);
}

ReferenceDecision arbitrate_reference(const LedgerRow* begin, const LedgerRow* end, std::uint32_t active) {
  const Tally t(begin, end);
  if (!t.is_rejected(0)) return ReferenceDecision::kUse;
  if (!t.every_gyro_rejected(active)) return ReferenceDecision::kNoCall;
  if (t.stands(Tally::kDrift)) return ReferenceDecision::kMatchDrift;
  if (t.stands(Tally::kCalibration)) return ReferenceDecision::kNoCall;
  if (t.stands(Tally::kReference) && t.is_rejected(Tally::kDrift)) return ReferenceDecision::kReject;
  return ReferenceDecision::kNoCall;
}

bool arbitrate_calibration(const LedgerRow* begin, const LedgerRow* end, std::uint32_t active) {
  const Tally t(begin, end);
  return t.is_rejected(0) && t.every_gyro_rejected(active) && t.stands(Tally::kCalibration);
}

const char* to_string(ReferenceDecision decision) {
  switch (decision) {
    case ReferenceDecision::kUse:
      return "use";
    case ReferenceDecision::kReject:
      return "reject";
    case ReferenceDecision::kMatchDrift:
      return "match drift";
    case ReferenceDecision::kNoCall:
      break;
  }
  return "no call";
}

}  // namespace tetra::fdi

namespace tetra::fdi::detail {

EvidenceSource source_of(Evidence evidence) {
  switch (evidence) {
    case Evidence::kInvalid:
      return EvidenceSource::kInvalid;
    case Evidence::kTimeout:
      return EvidenceSource::kTimeout;
    case Evidence::kRepeated:
      return EvidenceSource::kRepeated;
    case Evidence::kZero:
      return EvidenceSource::kZero;
    case Evidence::kVariance:
      return EvidenceSource::kVariance;
    case Evidence::kNoiseLevel:
      return EvidenceSource::kNoiseLevel;
    case Evidence::kRecurringSpikes:
      return EvidenceSource::kRecurringSpikes;
    case Evidence::kReference:
      return EvidenceSource::kReferenceWindow;
    case Evidence::kGlt:
      return EvidenceSource::kGlt;
    case Evidence::kNone:
    case Evidence::kOnset:
      break;
  }
  return EvidenceSource::kOnset;
}

EvidenceSource source_of(DetectionTest test) {
  switch (test) {
    case DetectionTest::kChi2:
      return EvidenceSource::kChi2;
    case DetectionTest::kCusum:
      return EvidenceSource::kCusum;
    case DetectionTest::kLevel:
      return EvidenceSource::kLevel;
    case DetectionTest::kOnset:
      return EvidenceSource::kJump;
    case DetectionTest::kReference:
      return EvidenceSource::kReferenceTest;
    case DetectionTest::kSignature:
    case DetectionTest::kNone:
      break;
  }
  return EvidenceSource::kChi2;
}

}  // namespace tetra::fdi::detail
