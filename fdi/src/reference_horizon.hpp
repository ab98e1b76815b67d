#pragma once
// The fusion horizon of the attitude reference (docs/fdi.md, "Late references"): a star tracker's sample
// arrives 50–300 ms after the time it was taken, when the epoch of its stamp has already been fused. The
// horizon keeps, for the epochs of the last `reference_horizon_s`, the rotation the gyros alone integrated
// (the filter's propagation, without the corrections references made). A sample stamped at a buffered
// epoch k is fused at its own time: its innovation is the one it has against the estimate at k, carried to
// now along the gyros' rotation since k, q_ref(now) = q_ref(k) ⊗ G_k⁻¹ ⊗ G_prev ⊗ exp(ω Δt) (G the gyros'
// cumulative rotation; the last step, not propagated yet, on the previous rate). One older than the
// horizon, or with no buffered epoch within half a period of its stamp, is too late: left out, counted and
// said (the pipeline's `reference_late` event). Bounded: the ring is sized once, when the period is known.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

//! Where a reference sample stands against the horizon.
enum class ReferenceAge : std::uint8_t {
  kInTime,   //!< stamped at this epoch (within half a period): used as it is
  kDelayed,  //!< stamped at a buffered epoch: carried to now
  kTooLate   //!< beyond the horizon (or no buffered epoch at its stamp): left out
};

struct PlacedReference {
  ReferenceAge age = ReferenceAge::kInTime;
  Quaternion q_RB = Quaternion::Identity();  //!< body → reference, at this epoch's time
  double late_s = 0.0;                       //!< [s] this epoch's time minus the reference's stamp
};

class ReferenceHorizon {
 public:
  //! `horizon_s` ≥ 0 (0: every reference stamped before its epoch is too late).
  explicit ReferenceHorizon(double horizon_s) : horizon_s_(horizon_s) {}

  //! Sizes the ring for the sample period (once; later calls with another period re-size it).
  void prepare(double period_s);
  //! Forgets every epoch (a reset, a gap).
  void reset();
  //! The end of the epoch at `stamp_ns`: the attitude after its propagation and before its reference, and
  //! the final one (after the reference).
  void record(std::int64_t stamp_ns, const Quaternion& q_propagated_RB, const Quaternion& q_final_RB);
  //! A reference stamped `ref_ns` reaching the epoch at `now_ns` (before that epoch's propagation over
  //! `dt_s` at about `omega_BR_B_rad_s`, the previous rate).
  PlacedReference place(std::int64_t ref_ns, const Quaternion& q_ref_RB, std::int64_t now_ns,
                        const Eigen::Vector3d& omega_BR_B_rad_s, double dt_s) const;
  //! The pipeline's one call per epoch with a reference: the sample at this epoch's time, or none when it is
  //! too late — counted in `counters` (reference_delayed, reference_too_late), and the first of a run of
  //! too-late samples reported by a `reference_late` event appended to `events`.
  std::optional<Quaternion> admit(const Epoch& epoch, const Quaternion& q_ref_RB,
                                  const Eigen::Vector3d& omega_BR_B_rad_s, double dt_s, Counters& counters,
                                  std::vector<FdiEvent>& events);
  double horizon_s() const { return horizon_s_; }

 private:
  struct Entry {
    std::int64_t stamp_ns = 0;
    Quaternion gyro_RB = Quaternion::Identity();  //!< the gyros' cumulative rotation up to this epoch
  };
  double horizon_s_ = 0.0;
  std::int64_t period_ns_ = 0;
  std::vector<Entry> ring_;  //!< the newest `count_` epochs, ending at `head_`
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  bool has_final_ = false;
  bool late_run_ = false;  //!< the last reference was too late (reported once per run)
  Quaternion last_final_RB_ = Quaternion::Identity();
  Entry newest_;  //!< the newest epoch recorded (kept while the ring is not sized yet)
  Quaternion gyro_RB_ = Quaternion::Identity();
};

}  // namespace tetra::fdi::detail
