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

int arbitrate(const LedgerRow* begin, const LedgerRow* end, std::uint32_t active, bool reference_exists) {
  // Per hypothesis: did any row reject it, did any row find it consistent.
  std::array<bool, kMaxGyros + 2> rejected{};
  std::array<bool, kMaxGyros + 2> consistent{};
  const auto slot = [](std::uint8_t h) {
    return h == kHypothesisReference ? kMaxGyros + 1 : static_cast<int>(h);
  };
  for (const LedgerRow* row_it = begin; row_it != end; ++row_it) {
    const LedgerRow& row = *row_it;
    const int s = slot(row.hypothesis);
    if (s > kMaxGyros + 1) continue;
    rejected[static_cast<std::size_t>(s)] |= row.verdict == RowVerdict::kRejected;
    consistent[static_cast<std::size_t>(s)] |= row.verdict == RowVerdict::kConsistent;
  }
  if (!rejected[0]) return 0;  // no fault shown
  if (reference_exists && !rejected[static_cast<std::size_t>(kMaxGyros + 1)]) return 0;
  int standing = 0;
  for (int j = 1; j <= kMaxGyros; ++j) {
    if (!has_gyro(active, j)) continue;
    const auto u = static_cast<std::size_t>(j);
    if (rejected[u]) continue;
    if (!consistent[u] || standing != 0) return 0;  // no call on Hj, or a second hypothesis standing
    standing = j;
  }
  return standing;
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
