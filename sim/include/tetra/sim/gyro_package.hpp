#pragma once
// The simulated gyro package: one GyroChannel per gyro, a warm-up's bias transient (thermal.hpp), the
// injected faults (fault.hpp), dropped samples and the star-tracker-like attitude reference. It turns the
// sensed inertial body rate at a sample time into the raw outputs of that epoch. Shared by the open-loop
// Simulator (truth from the closed-form motion) and the closed-loop simulator (truth from the rigid-body
// dynamics), so both draw the same seeded streams in the same order.

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/gyro_model.hpp"
#include "tetra/sim/random.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::sim {

class GyroPackage {
 public:
  //! `faults` are all the faults of the run (the scenario's and the options'), already validated.
  GyroPackage(const Scenario& scenario, std::vector<FaultSpec> faults, std::uint64_t seed);

  //! Back to the first epoch with the same seed.
  void reset();
  //! Raw outputs [V] of every gyro for the sensed inertial rate `sensed_dps` [deg/s] at time `t_s`;
  //! `present[i]` = 0 where gyro i delivered no sample (then raw_V[i] is NaN).
  void sample(const Eigen::Vector3d& sensed_dps, double t_s, std::vector<double>& raw_V,
              std::vector<std::uint8_t>& present);
  //! The attitude reference of epoch `k` (none between reference periods): the truth `latency_s` earlier ⊗
  //! exp(δθ + slow bias + mis-identification), none for a dropout (`drop_probability`). Called for every
  //! epoch (it keeps the truth's recent past).
  std::optional<Quaternion> reference(std::size_t k, const Quaternion& truth_q_RB);

  const std::vector<FaultSpec>& faults() const { return faults_; }
  int gyro_count() const { return static_cast<int>(channels_.size()); }

 private:
  double apply_faults(int i, double v, double t_s, bool& present);

  std::vector<FaultSpec> faults_;
  std::uint64_t seed_;
  double rate_hz_;           //!< [Hz] gyro sampling rate
  double drop_probability_;  //!< per sample
  ReferenceOptions reference_options_;
  Calibration unit_;
  GyroModelOptions model_;
  ThermalOptions thermal_;
  std::vector<GyroChannel> channels_;
  Rng reference_rng_;
  Rng reference_drop_rng_;  //!< its own stream: dropouts leave the noise samples as they were
  std::vector<Rng> drop_rngs_;
  std::vector<double> last_output_V_;  //!< per gyro: last delivered value
  std::vector<std::uint8_t> has_last_output_;
  std::vector<std::optional<double>> stuck_value_V_;  //!< per fault
  std::vector<std::uint8_t> spike_done_;              //!< per fault
  std::int64_t last_reference_period_ = -1;
  std::deque<std::pair<double, Quaternion>> truth_history_;  //!< [s], q_RB: the last latency_s of truth
};

}  // namespace tetra::sim
