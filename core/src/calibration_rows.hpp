#pragma once
// The body rate of every row of an interpreted turntable log, recomputed pass by pass (never stored per
// row). Private to tetra::core: shared by the motion analysis and the estimators.

#include <cstddef>
#include <cstdio>
#include <functional>

#include <Eigen/Core>

#include "tetra/core/calibration.hpp"
#include "tetra/core/turntable_rows.hpp"

namespace tetra::calibration_detail {

//! [deg/s] table rate and Earth rate in B of a row of sequence `m` at encoder angles (inner, outer).
struct BodyRate {
  Eigen::Vector3d table_dps;
  Eigen::Vector3d earth_dps;
  Eigen::Vector3d total_dps() const { return table_dps + earth_dps; }
};
BodyRate body_rate(const SequenceMotion& m, double inner_deg, double outer_deg, double latitude_rad);

//! The body rates of a log's rows, in file order, as the first pass over them computed them.
}  // namespace tetra::calibration_detail

namespace tetra {
struct BodyRateCache {
  std::FILE* file = nullptr;
  bool ready = false;   //!< every row's rate is in the file
  bool failed = false;  //!< the file could not be written: rates are computed in every pass
  BodyRateCache() = default;
  BodyRateCache(const BodyRateCache&) = delete;
  BodyRateCache& operator=(const BodyRateCache&) = delete;
  ~BodyRateCache() {
    if (file != nullptr) std::fclose(file);
  }
};
}  // namespace tetra

namespace tetra::calibration_detail {

//! Visits every row in file order with the index of its sequence in motion.sequences and ω_B [deg/s].
using RateRowVisitor = std::function<void(const TurntableRow& row, std::size_t sequence_index,
                                          const Eigen::Vector3d& rate_B_dps)>;
Status for_each_rate_row(const TurntableRows& rows, const TurntableMotion& motion,
                         const RateRowVisitor& visit);

}  // namespace tetra::calibration_detail
