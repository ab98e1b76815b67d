#pragma once
// Gyro model of the simulator: ordered, seeded stages, each callable alone for testing.
//
//   true rate along the as-built axis h_i  r = h_i · ω_B                          [deg/s]
//   1. scale factor and bias                v = s_i · r + β_i                       [V]
//   2. white rate noise (ARW, N)            + s_i · N/√Δt · n_k
//   3. bias instability (B)                 + s_i · b_k, first-order Gauss–Markov (see below)
//   4. rate random walk (K) and ramp (R)    + s_i · (w_k + R·t),  w_k = w_{k−1} + K·√Δt · n_k
//   5. quantization (Q)                     angle quantization of the integrated output
//   6. saturation                           output clamped to the measuring range
//   (7. faults: applied by the Simulator, see fault.hpp)
//
// The noise coefficients are the IEEE Std 952 terms of the calibration file's `noise:` section,
// in deg/s-based units; a term absent there is not simulated.
//
// Bias instability: IEEE 952's flat Allan floor √(2 ln2/π)·B = 0.664·B is produced by a
// first-order Gauss–Markov process with correlation time T_c (option, default 100 s) and stationary
// standard deviation σ_GM = 1.0760·B: the Allan deviation of such a process peaks at 0.6174·σ_GM
// at τ = 1.893·T_c, so its peak equals the floor 0.664·B. (A single Gauss–Markov process is a hump,
// not a flat floor: away from τ ≈ 2·T_c it falls below 0.664·B.) The process starts in its
// stationary distribution.
//
// Quantization: the output is the difference of the quantized integrated output (angle
// quantization, step δ = √12·Q [deg], i.e. |s_i|·δ [V·s]), so each sample is an integer multiple of
// |s_i|·δ/Δt [V] and the integrated output never drifts more than one step from the true one.
// Its Allan variance is 3Q²/τ².

#include <cstdint>
#include <optional>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/correlated_noise.hpp"
#include "tetra/sim/random.hpp"

namespace tetra::sim {

//! σ_GM / B: stationary σ of the Gauss–Markov process whose Allan peak equals 0.664·B (shared with the
//! calibration's noise model, tetra/core/correlated_noise.hpp).
using tetra::kGaussMarkovSigmaPerB;
//! τ / T_c at which the Allan deviation of a first-order Gauss–Markov process peaks.
inline constexpr double kGaussMarkovPeakTauPerTc = 1.893;

//! Model options that the calibration file does not carry.
struct GyroModelOptions {
  double bias_instability_correlation_s = 100.0;  //!< [s] T_c of the bias-instability process
  std::optional<double> range_dps;                //!< [deg/s] measuring range; none = no saturation
};

//! One gyro's model with its own random streams. Not thread-safe; one per gyro.
class GyroChannel {
 public:
  //! `gyro_index0` selects the random streams; `dt_s` is the nominal sampling interval.
  GyroChannel(const GyroCalibration& gyro, const GyroModelOptions& options, double dt_s, std::uint64_t seed,
              int gyro_index0);

  //! Stage 1: [V] from the true rate along the axis [deg/s].
  double scale_and_bias_V(double rate_dps) const { return scale_V_per_dps_ * rate_dps + bias_V_; }
  //! Stage 2: [deg/s] next white-noise sample (0 without N).
  double white_noise_dps();
  //! Stage 3: [deg/s] next bias-instability sample (0 without B).
  double bias_instability_dps();
  //! Stage 4: [deg/s] next rate-random-walk + rate-ramp value at time `t_s` (0 without K and R).
  double rate_random_walk_dps(double t_s);
  //! Stage 5: [V] quantized output (identity without Q). Stateful: call once per epoch, in order.
  double quantize_V(double v);
  //! Stage 6: [V] clamped to the measuring range (identity without a range).
  double saturate_V(double v) const;

  //! The whole chain for the true body rate `omega_B_dps` at time `t_s`: [V].
  double sample_V(const Eigen::Vector3d& omega_B_dps, double t_s);
  //! The whole chain for a rate already projected on the axis.
  double sample_axis_V(double rate_dps, double t_s);

  //! [deg/s] the white-noise sample drawn by the last white_noise_dps() call (0 before).
  double last_white_noise_dps() const { return last_white_dps_; }
  double quantization_step_V() const;  //!< [V] output step of stage 5 (0 without Q)
  double gauss_markov_sigma_dps() const { return gm_sigma_dps_; }  //!< [deg/s] σ_GM
  const Eigen::Vector3d& axis_B() const { return axis_B_; }
  double scale_V_per_dps() const { return scale_V_per_dps_; }
  double bias_V() const { return bias_V_; }

 private:
  Eigen::Vector3d axis_B_;        //!< unit sensing axis in B
  double scale_V_per_dps_;        //!< [V/(deg/s)]
  double bias_V_;                 //!< [V]
  double dt_s_;                   //!< [s] nominal sampling interval
  double white_sigma_dps_ = 0.0;  //!< [deg/s] N/√Δt
  double last_white_dps_ = 0.0;   //!< [deg/s] last white-noise sample
  double gm_sigma_dps_ = 0.0;     //!< [deg/s] stationary σ of the bias-instability process
  double gm_phi_ = 0.0;           //!< exp(−Δt/T_c)
  double gm_drive_dps_ = 0.0;     //!< [deg/s] σ_GM·√(1−φ²)
  double gm_state_dps_ = 0.0;     //!< [deg/s]
  bool gm_started_ = false;
  double rrw_step_dps_ = 0.0;   //!< [deg/s] K·√Δt
  double rrw_state_dps_ = 0.0;  //!< [deg/s]
  double ramp_dps_s_ = 0.0;     //!< [deg/s²] R
  double quant_step_Vs_ = 0.0;  //!< [V·s] |s|·√12·Q
  double quant_integral_Vs_ = 0.0;
  double quant_last_count_ = 0.0;
  double sat_low_V_ = 0.0;
  double sat_high_V_ = 0.0;
  bool saturate_ = false;
  Rng white_rng_;
  Rng gm_rng_;
  Rng rrw_rng_;
};

}  // namespace tetra::sim
