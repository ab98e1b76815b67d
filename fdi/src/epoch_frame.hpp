#pragma once
// What flows between the pipeline's stages within one epoch, and what a stage may ask the gyro set to do.
// Preallocated once (size N); nothing here allocates per epoch.

#include <cstdint>
#include <optional>
#include <vector>

#include "evidence_rows.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

struct EpochFrame {
  std::int64_t now_ns = 0;      //!< [ns] epoch time
  double dt_s = 0.0;            //!< [s] since the previous accepted epoch (0 on the first)
  std::int64_t index = -1;      //!< accepted-epoch counter
  std::vector<double> y_rad_s;  //!< [rad/s] calibrated rate per gyro (valid samples only)
  std::vector<double> raw;      //!< [V] (or [deg/s]) raw sample per gyro (valid samples only)
  GyroMask valid = 0;           //!< present and valid samples
  GyroMask usable = 0;          //!< valid, not excluded, not an outlier: the rate solution's subset
  //! The epoch's attitude reference when it is a unit quaternion (finite, norm 1 within 1e-3; normalized):
  //! anything else is left out and counted (Counters::reference_invalid).
  std::optional<Quaternion> reference_q_RB;

  void resize(int n) {
    y_rad_s.assign(static_cast<std::size_t>(n), 0.0);
    raw.assign(static_cast<std::size_t>(n), 0.0);
  }
};

//! A stage's finding that one gyro alone explains the data: the pipeline excludes it.
struct Isolation {
  int gyro = 0;  //!< 1..N
  FaultKind kind = FaultKind::kUnknown;
  Evidence evidence = Evidence::kNone;
  DetectionTest test = DetectionTest::kNone;
  double statistic = 0.0;
  EvidenceRows rows;  //!< the rows the finding rests on, per hypothesis (the arbiter reads them)
};

//! Up to N isolations found in one pass of a stage (capacity reserved once).
using Isolations = std::vector<Isolation>;

}  // namespace tetra::fdi::detail
