#pragma once
// One-epoch jump test (docs/fdi.md, "One-epoch jump test"): a significant jump of the parity that exactly one
// single-gyro hypothesis explains with a physically possible motion leaves that gyro's sample out of this
// epoch. An outlier that goes away was a spike; one that persists `onset_confirm_epochs` is an abrupt step.

#include <cstdint>
#include <vector>

#include "epoch_frame.hpp"
#include "gyro_series.hpp"
#include "subset_cache.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

class OutlierGate {
 public:
  OutlierGate(int n_gyros, const PipelineConfig& config);

  //! Leaves this epoch's outlier (if any) out of `frame.usable`, records spikes in `series`, and appends a
  //! persistent outlier (an abrupt step) to `out`.
  void update(EpochFrame& frame, SubsetCache& subsets, GyroSeries& series, Counters& counters,
              Isolations& out);
  //! The epoch's gyros to publish among `active`: `frame.usable`, with the sample the jump test left out of
  //! this epoch back when a restart (an isolation) followed its call — the jump was the isolated gyro's, one
  //! fault, so the call on another gyro is withdrawn rather than leave fewer gyros than delivered.
  GyroMask usable(const EpochFrame& frame, GyroMask active) const {
    return (frame.usable | (withdrawn_ ? left_out_ : GyroMask{0})) & active;
  }
  //! Outlier runs of this gyro (> 0: its sample is being left out).
  int outlier_run(int id) const { return tracks_[static_cast<std::size_t>(id - 1)].outlier_run; }
  //! This epoch's parity difference of consecutive samples, the body within the motion bound on both steps
  //! (parity_spread.hpp): its χ² `u` (NaN: none this epoch), degrees of freedom and the jump threshold.
  double spread_sample() const { return spread_sample_; }
  int spread_dof() const { return spread_dof_; }
  double spread_cap() const { return spread_cap_; }
  //! This epoch's samples followed the previous epoch's, every gyro of the set in both, no outlier run.
  bool consecutive() const { return consecutive_; }
  //! Forgets every gyro's last good sample and outlier run (after a reconfiguration).
  void restart();
  void reset();

 private:
  struct Track {
    bool has_last_good = false;
    double last_good_y = 0.0;  //!< [rad/s]
    std::int64_t last_good_ns = 0;
    int outlier_run = 0;
    double outlier_first_raw = 0.0;
    bool outlier_repeated = true;
  };
  //! The single gyro whose jump explains the parity jump with a possible motion, or 0.
  int jump_culprit(const EpochFrame& frame, SubsetCache& subsets, const GyroSeries& series);
  //! The rate change that the gyros of `h` imply over `dt_s` is within the acceleration bound and its noise.
  bool possible_motion(const Subset& h, double dt_s, const GyroSeries& series,
                       const SubsetCache& subsets) const;
  //! [rad/s] onset_sigma × 1σ of the rate change the gyros of `h` imply from their sample noise alone (kept
  //! per subset and sample period).
  double motion_noise(const Subset& h, const GyroSeries& series, double sqrt_period) const;
  //! The confirmed step of gyro `id`, its kind and its ledger rows.
  Isolation classify_step(int id, const EpochFrame& frame, const GyroSeries& series,
                          double sqrt_period) const;
  Isolation step_kind(int id, const EpochFrame& frame, const GyroSeries& series, double sqrt_period) const;

  const PipelineConfig& config_;
  std::vector<Track> tracks_;
  std::vector<double> dy_;                    //!< [rad/s] change of each gyro since its last good sample
  std::vector<double> p_;                     //!< parity scratch
  mutable std::vector<double> motion_noise_;  //!< by subset mask (NaN: not yet computed); empty for N > 8
  mutable double motion_noise_period_ = 0.0;  //!< [√s] the sample period's root they were computed for
  bool fast_motion_ = false;  //!< the last step without a jump turned the body beyond the acceleration bound
  GyroMask left_out_ = 0;     //!< the gyro this epoch's call left out of `frame.usable` (0: none)
  bool withdrawn_ = false;    //!< a restart followed this epoch's call: it no longer stands
  std::int64_t previous_ns_ = 0;  //!< [ns] the epoch judged before this one
  double spread_sample_ = 0.0;    //!< this epoch's spread sample χ² (NaN: none)
  int spread_dof_ = 1;
  double spread_cap_ = 0.0;
  bool consecutive_ = false;
};

}  // namespace tetra::fdi::detail
