#pragma once
// Turntable simulation: the 16-sequence rotation plan of seed Table 3 on a two-axis table, written as
// the turntable log of docs/interfaces.md §2.1 (the input of `tetra calibrate`).
//
// Sequences (w = table rate; odd sequence +w, even −w; the rotating gimbal starts at encoder 0):
//   1, 2   inner rotating, outer fixed at   0°       9, 10  outer rotating, inner fixed at  90°
//   3, 4   inner rotating, outer fixed at 180°      11, 12  outer rotating, inner fixed at −90°
//   5, 6   outer rotating, inner fixed at   0°      13, 14  outer rotating, inner fixed at  30°
//   7, 8   outer rotating, inner fixed at 180°      15, 16  outer rotating, inner fixed at −30°
// Body rates come from the kinematics of docs/interfaces.md §1 (tetra/core/frames.hpp), not from the signs
// printed in Table 3: e.g. sequence 9 (inner at 90°, outer +w) turns the body about −Z.
// Each sequence lasts `revolutions` full turns, sampled at `rate_hz` from the start of the turn
// (the last sample is one step before the turn closes), sequences back to back on one time axis.

#include <cstdint>
#include <vector>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/result.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/sim/gyro_model.hpp"

namespace tetra::sim {

struct TurntablePlan {
  double table_rate_dps = 6.0;  //!< [deg/s] commanded gimbal rate
  double revolutions = 1.0;     //!< revolutions per sequence
  double rate_hz = 10.0;        //!< [Hz] sampling rate
  double latitude_deg = -23.2;  //!< [deg] geodetic latitude of the table
  std::vector<int> order;       //!< sequence numbers 1..16 in the order run; empty = 1..16
  bool wrap_angles = false;     //!< encoder angles written wrapped to (-180, 180] instead of unwrapped
};

//! One sequence of the plan: which gimbal turns, the other's fixed angle, the direction.
struct TurntableSequence {
  bool inner_rotates = true;  //!< true: inner gimbal turns, outer fixed; false: the reverse
  double fixed_deg = 0.0;     //!< [deg] encoder angle of the fixed gimbal
  double direction = 1.0;     //!< +1 or −1
};

//! The sequence `number` (1..16) of seed Table 3.
TurntableSequence turntable_sequence(int number);

//! Wraps an angle to (−180, 180] [deg].
double wrap_deg(double angle_deg);

//! The 16 sequences of seed Table 3 as encoder angles (fixed angle of one gimbal, the other rotating +w then
//! -w), body rates and Earth rate in B from the kinematics of docs/interfaces.md §1 (NOT Table 3's body-rate
//! signs), gyro outputs from `unit` (scale factors, biases, axes, and the noise terms present in its `noise:`
//! sections).
Result<TurntableLog> simulate_turntable(const Calibration& unit, const TurntablePlan& plan,
                                        std::uint64_t seed);

//! The same with gyro-model options (bias-instability correlation time, measuring range).
Result<TurntableLog> simulate_turntable(const Calibration& unit, const TurntablePlan& plan,
                                        std::uint64_t seed, const GyroModelOptions& model);

}  // namespace tetra::sim
