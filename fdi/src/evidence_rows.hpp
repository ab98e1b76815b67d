#pragma once
// The rows of one decision (docs/fdi.md, "The ledger and the arbiter"): what one source, and the detection
// that opened the episode, wrote per hypothesis. Fixed capacity, so a stage's finding allocates nothing.

#include <array>

#include "tetra/core/geometry.hpp"
#include "tetra/fdi/ledger.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

class EvidenceRows {
 public:
  //! The most one decision holds: a source's N + 2 (H0, H1…HN, Href), the filter-bias check's N + 1
  //! (bias_fit, bias_persists), the episode's detection rows (up to 4), the calibration's two (Hcal) and the
  //! kind's one (drift_shape): 2N + 10, for every N the geometry allows; add() beyond it would drop a row
  //! unseen.
  static constexpr int kCapacity = 2 * kMaxGyros + 10;

  void clear() { n_ = 0; }
  void add(const LedgerRow& row) {
    if (n_ < kCapacity) rows_[static_cast<std::size_t>(n_++)] = row;
  }
  void add(const EvidenceRows& other) {
    for (const LedgerRow& row : other) add(row);
  }
  //! Rows stating that `culprit`'s own signal shows its fault: Hculprit consistent, every other active gyro's
  //! hypothesis (which holds `culprit` healthy), H0 and Href rejected, all by the same statistic.
  void own_signal(EvidenceSource source, int culprit, GyroMask active, double statistic, double threshold);
  //! The two rows of a detection: H0 and Href (every gyro healthy) rejected by `statistic` above `threshold`.
  void detection(EvidenceSource source, double statistic, double threshold, int dof);

  const LedgerRow* begin() const { return rows_.data(); }
  const LedgerRow* end() const { return rows_.data() + n_; }
  int size() const { return n_; }
  bool empty() const { return n_ == 0; }

 private:
  std::array<LedgerRow, kCapacity> rows_{};
  int n_ = 0;
};

//! fdi::arbitrate_detection over the rows.
inline bool arbitrate_detection(const EvidenceRows& rows) {
  return fdi::arbitrate_detection(rows.begin(), rows.end());
}

//! fdi::arbitrate over the rows.
inline int arbitrate(const EvidenceRows& rows, GyroMask active, bool reference_exists) {
  return fdi::arbitrate(rows.begin(), rows.end(), active, reference_exists);
}

//! The source of an isolation's evidence, and of a detection's test.
EvidenceSource source_of(Evidence evidence);
EvidenceSource source_of(DetectionTest test);

}  // namespace tetra::fdi::detail
