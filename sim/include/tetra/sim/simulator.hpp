#pragma once
// The streaming simulator: one epoch at a time (for real-time publishing), or a whole log in memory
// (for tests of other components), or straight to files (tetra sim).
//
// Epoch k has the nominal time k/rate; with jitter the sample time (stamp) moves by a seeded
// uniform offset and the truth and gyro rates are evaluated at that time. Gyro rates are the
// instantaneous inertial body rate at the sample time, projected on each as-built axis.
// Reference samples: at the first gyro epoch of each reference period (k·f_ref/f crosses an integer).

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/gyro_log.hpp"
#include "tetra/core/interrupt.hpp"
#include "tetra/core/output_files.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"
#include "tetra/core/units.hpp"
#include "tetra/sim/gyro_model.hpp"
#include "tetra/sim/gyro_package.hpp"
#include "tetra/sim/motion.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::sim {

struct SimOptions {
  std::uint64_t seed = 1;         //!< same seed → same output, bit for bit
  std::vector<FaultSpec> faults;  //!< added to the scenario's own faults
};

struct SimEpoch {
  std::int64_t stamp_ns = 0;                 //!< [ns] sample time (with jitter)
  double time_s = 0.0;                       //!< [s] the same, as written in the log
  std::vector<double> raw_V;                 //!< [V] per gyro; NaN where invalid or not delivered
  std::vector<std::uint8_t> present;         //!< per gyro: 0 = no sample delivered
  std::optional<Quaternion> reference_q_RB;  //!< attitude reference on its epochs
  Quaternion truth_q_RB;                     //!< true attitude, body → reference frame R
  Eigen::Vector3d truth_omega_BR_B_rad_s;    //!< [rad/s] true rate of B relative to R, in B
  Eigen::Vector3d omega_BN_B_rad_s;          //!< [rad/s] true inertial rate of B (incl. Earth rate)
};

class Simulator {
 public:
  static Result<Simulator> create(const Scenario& scenario, const SimOptions& options);

  //! Fills `out` with the next epoch; false at the end (out untouched).
  bool next(SimEpoch& out);
  //! Back to epoch 0 with the same seed (the same epochs again).
  void reset();

  int gyro_count() const { return scenario_.unit.gyro_count(); }
  std::size_t epoch_count() const { return epochs_; }
  //! [ns] nominal interval between epochs (a real-time publisher paces on it).
  std::int64_t period_ns() const { return seconds_to_ns(1.0 / scenario_.rate_hz); }
  std::size_t epochs_done() const { return k_; }
  const Scenario& scenario() const { return scenario_; }
  const TruthMotion& motion() const { return motion_; }
  //! "# key=value" metadata describing the run (scenario, seed, frames, ACS bounds, faults...).
  std::vector<std::pair<std::string, std::string>> metadata() const;

 private:
  Simulator(Scenario scenario, SimOptions options, TruthMotion motion);

  Scenario scenario_;
  SimOptions options_;
  TruthMotion motion_;
  GyroPackage package_;  //!< gyros, faults (the scenario's and the options'), drops, reference
  std::size_t epochs_ = 0;
  std::size_t k_ = 0;
  Rng jitter_rng_;
};

//! The scenario's faults followed by the options'.
std::vector<FaultSpec> all_faults(const Scenario& scenario, const SimOptions& options);

//! Ground truth of a simulated run, one entry per epoch.
struct Truth {
  std::vector<double> time_s;                     //!< [s]
  std::vector<Quaternion> q_RB;                   //!< body → reference frame
  std::vector<Eigen::Vector3d> omega_BR_B_rad_s;  //!< [rad/s] rate of B relative to R, in B
  std::vector<Eigen::Vector3d> omega_BN_B_rad_s;  //!< [rad/s] inertial rate of B, in B
};

//! The whole run in memory as a gyro log (volts, with ref_* columns when the scenario has a
//! reference); the truth too when `truth` is given. `interrupt` (optional) is polled every 64 epochs
//! (epochs done of the run's); when it asks to stop the call returns interrupted().
Result<GyroLog> simulate_log(const Scenario& scenario, const SimOptions& options, Truth* truth = nullptr,
                             Interrupt* interrupt = nullptr);

//! Runs the simulator to files: the gyro log (docs/interfaces.md §2.2) and, if `truth_path` is not empty,
//! the truth (time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps: attitude body → R and rate of B relative to R).
//! `progress` is called now and then with the fraction done. Errors name the outputs "log" and "truth".
Status write_simulation(Simulator& simulator, const std::string& log_path, const std::string& truth_path,
                        void (*progress)(double fraction) = nullptr);
//! The same into outputs of a larger run (the caller's RunFiles commits them); `extra_metadata` (e.g.
//! provenance) follows the simulator's own "# key=value" lines. `truth` may be null.
Status write_simulation(Simulator& simulator, OutputFile& log, OutputFile* truth,
                        const std::vector<std::pair<std::string, std::string>>& extra_metadata,
                        void (*progress)(double fraction));

}  // namespace tetra::sim
