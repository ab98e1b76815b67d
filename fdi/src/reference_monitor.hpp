#pragma once
// Attitude-reference monitor (docs/fdi.md, "Attitude reference"): each gyro's integrated angle against the
// rotation the reference saw about that gyro's axis, over windows of `reference_window_s`. One gyro alone
// beyond the threshold, every other quiet, in `reference_confirm_count` consecutive windows isolates it.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "bias_hypothesis.hpp"
#include "epoch_frame.hpp"
#include "gyro_series.hpp"
#include "mekf.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

//! The reference's finding: the gyro and whether a scale error (rather than an offset) explains it.
struct ReferenceFinding {
  int gyro = 0;
  double statistic = 0.0;  //!< [σ] disagreement of the gyro
  bool scale = false;      //!< the error follows the rotation during a slew: a scale-factor error
  EvidenceRows rows;       //!< the comparison's ledger rows
};

//! "One gyro alone beyond the threshold, every other below half of it, in `count` consecutive comparisons":
//! the votes of one comparison (`begin`, `add` per gyro) and the run of comparisons that agree.
class LoneGyro {
 public:
  void begin();
  void add(int id, double z, double threshold);
  //! The gyro flagged alone by this and the previous `count` − 1 comparisons (at least `min_members` gyros
  //! compared), else 0; a confirmed gyro starts the run again.
  int confirm(int count, int min_members);
  double statistic() const { return stat_; }  //!< [σ] the flagged gyro's
  //! The last comparison as ledger rows: for each gyro j of `active`, Hj's statistic is the largest
  //! disagreement among the gyros it holds healthy (consistent at or below half the threshold, rejected
  //! above it); H0's the largest of all; Href rejected by the flagged gyro's when the others agree with the
  //! reference (a wrong reference would move them too). `judge_others` false: the other gyros' rows make no
  //! call (the filter's bias states, where a fault that is not a bias spreads: bias_fit judges them).
  void rows(EvidenceSource source, GyroMask active, EvidenceRows& out, bool judge_others = true) const;
  void reset() { run_gyro_ = run_ = 0; }
  //! A confirmed gyro that was not acted on: the next comparison that flags it alone confirms it again.
  void rearm(int id, int count) {
    run_gyro_ = id;
    run_ = count - 1;
  }

 private:
  int flagged_ = 0, loud_ = 0, culprit_ = 0, members_ = 0;
  double stat_ = 0.0;
  double threshold_ = 0.0;
  std::array<int, kMaxGyros> member_id_{};
  std::array<double, kMaxGyros> member_z_{};
  int run_gyro_ = 0;  //!< gyro flagged alone by the last comparisons
  int run_ = 0;       //!< how many in a row
};

class ReferenceMonitor {
 public:
  ReferenceMonitor(const Eigen::MatrixX3d& axes_B, const PipelineConfig& config);

  //! Integrates each active gyro's angle up to this epoch (trapezoid; a gyro without a usable sample
  //! contributes the rate estimate's projection), Earth rate `earth_B_rad_s` removed. `estimate_fresh`: the
  //! estimate is this epoch's (false: too few samples, the last one held) — a gyro that integrates a held
  //! estimate is left out of every comparison whose span contains that epoch.
  void integrate(const EpochFrame& frame, GyroMask excluded, const Eigen::Vector3d& omega_meas_B_rad_s,
                 const Eigen::Vector3d& earth_B_rad_s, bool estimate_fresh);
  //! A reference sample: compares the last window; a confirmed single-gyro disagreement is returned.
  std::optional<ReferenceFinding> update(std::int64_t now_ns, const Quaternion& q_RB, GyroMask excluded,
                                         const GyroSeries& series);
  //! During a fault episode, at a reference sample: the attitude filter's bias estimates. One active gyro's
  //! bias beyond `reference_threshold_sigma` of its fault-free spread (Mekf::bias_z), every other within half
  //! of it, at `reference_confirm_count` consecutive samples isolates it.
  std::optional<ReferenceFinding> filter_update(const Mekf& filter, GyroMask active);
  //! The filter's finding for `id` was not confirmed by the fault-model check: the next sample that flags
  //! `id` alone is a finding again (the check is retried at every sample rather than after a new run).
  void filter_rearm(int id) { filter_.rearm(id, design::reference_confirm_count); }
  //! Each active gyro's disagreement with the reference from the first snapshot at or after `from_ns` to the
  //! last one (this sample's); false when that span is shorter than `min_span_s`.
  bool span(std::int64_t from_ns, double min_span_s, GyroMask excluded, const GyroSeries& series,
            SpanDisagreement& out) const;
  //! Gyro `id`'s disagreement over `span` follows the rotation about its axis (a scale error, see `update`).
  bool span_scale(int id, const SpanDisagreement& span) const { return scale_significant(id, span.start); }
  //! The windows and their runs of findings start again: a reinstated gyro's angle has a gap; after an
  //! isolation, an angle may have integrated the rate estimate of the old set while its own sample was left
  //! out as an outlier, and the findings so far were comparisons over that.
  void restart_windows() {
    snap_count_ = 0;
    windows_.reset();
    filter_.reset();
  }
  void reset();
  //! [rad] 1σ per axis of the reference samples from now on (reference_sigma_arcsec until re-estimated).
  void set_reference_sigma_rad(double sigma_rad) { sigma_ref_rad_ = sigma_rad; }

 private:
  static constexpr int kSnapshots = 512;  //!< reference snapshots kept
  struct Track {
    double angle_rad = 0.0;      //!< ∫ (y_i − h_i·ω_e) dt (trapezoid)
    double prev_int_y = 0.0;     //!< [rad/s] rate integrated at the previous epoch
    double ref_angle_rad = 0.0;  //!< Σ h_i·log(q_{k−1}* q_k) over the reference's own increments
    std::int64_t held_ns = -1;   //!< [ns] the last epoch whose angle increment used a held rate estimate
  };
  void snapshot(std::int64_t now_ns, const Quaternion& q);
  //! Index of the first kept snapshot taken at or after `from_ns` among those before `end`, else `end`.
  int first_snapshot_from(std::int64_t from_ns, int end) const;
  //! Index of the oldest snapshot inside the window and at least half a window old, or −1.
  int window_start(std::int64_t now_ns) const;
  bool scale_significant(int culprit, int old) const;
  //! [rad] 1σ of a healthy gyro's disagreement over `span_s` with rotation `rot_rad` about its axis.
  double disagreement_sigma(const GyroConstants& c, double span_s, double rot_rad) const;
  //! [rad] the disagreement `err` less the bound on what the gyro's scale factor and axis errors within
  //! `calibration_error_sigmas` of their stated σ make of the rotation between snapshots `old` and `last`:
  //! e·(σ_s·|rot| + Σ_j σ_h,j·|Θ_j|), Θ the reference's rotation in B (0 when |err| is below it).
  double beyond_calibration(const GyroConstants& c, double err, double rot, int old, int last) const;
  double snap_angle(int k, int i) const { return snap_angle_[slot(k) * n_ + static_cast<std::size_t>(i)]; }
  double snap_ref(int k, int i) const { return snap_ref_[slot(k) * n_ + static_cast<std::size_t>(i)]; }
  static std::size_t slot(int k) { return static_cast<std::size_t>(k % kSnapshots); }

  Eigen::MatrixX3d axes_B_;
  const PipelineConfig& config_;
  std::size_t n_;
  std::vector<Track> tracks_;
  std::vector<std::int64_t> snap_ns_;
  std::vector<Quaternion> snap_q_;
  std::vector<double> snap_angle_;           //!< kSnapshots×N
  std::vector<double> snap_ref_;             //!< kSnapshots×N
  std::vector<Eigen::Vector3d> snap_theta_;  //!< [rad] Σ of the reference's increments in B, per snapshot
  int snap_count_ = 0;                       //!< total pushed
  LoneGyro windows_;                         //!< the windows' comparisons
  LoneGyro filter_;                          //!< the filter's bias estimates at reference samples
  double sigma_ref_rad_ = 0.0;               //!< [rad] 1σ of a reference sample per axis
};

}  // namespace tetra::fdi::detail
