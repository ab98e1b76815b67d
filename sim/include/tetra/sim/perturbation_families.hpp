#pragma once
// Seeded families of perturbed runs for the fusion's acceptance campaign and, later, a Monte Carlo dispersion
// layer (docs/fdi.md, "Perturbation families"). Each family is one kind of departure from the ideal: a gyro
// fault at the start, middle or end of an agile slew, a lossy data path, a gap, a failing star tracker, a
// calibration off by up to twice its stated 1σ, a calibration without noise, a second fault once redundancy
// is exhausted, a warm-up. `perturbed_run(family, seed, index)` is a pure function: the same three numbers
// give the same run, bit for bit, whatever was drawn before; indices cover the family's cases in turn (slew
// axis and timing, fault kind, gyro count) and the seed varies the draws within them. Knows nothing of DDS or
// of the fusion's types: what the fusion must be told (its calibration, sample period, acceleration bound, an
// operator exclusion, a gap in delivery) is carried as plain data.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tetra/core/calibration_file.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::sim {

enum class Family {
  kFaultInSlew,  //!< one gyro fault at a slew's start, middle or end (slews up to 45° in 10 s)
  kDataPath,     //!< fault-free, 0–20 % of samples dropped, time jitter up to ±5 ms
  kGap,          //!< fault-free, 10–30 s with no epoch delivered, mid-slew or in orbit
  kReference,    //!< fault-free gyros, a late / noisy / biased / mis-identified star tracker
  kCalibration,  //!< scale and axis errors up to 2× the calibration's stated 1σ (a fault in 1/3)
  kCalibrationWithoutNoise,  //!< the fusion's calibration has no noise: section (a fault in 1/3)
  kSecondFault,              //!< three gyros and the reference, a fault on one of them (redundancy exhausted)
  kWarmUp,     //!< every gyro's bias follows a temperature transient, each by its own coefficient (a fault in
               //!< 1/3)
  kDataSheet,  //!< the fusion given a data-sheet calibration: scale factors 10–30 % off, axes by mrad, no σ
  kNoisyUnit,  //!< each gyro's true white noise and bias instability 0.5–3 times the stated (a fault in 1/3)
};
inline constexpr int kFamilyCount = 10;

std::string_view family_name(Family family);
std::optional<Family> family_from_name(std::string_view name);
//! Every family, in the enum's order.
std::vector<Family> all_families();

//! What the star tracker does wrong in a run (none: healthy).
enum class ReferenceFailure { kNone, kLate, kNoisy, kBiasStep, kBiasRamp, kMisidentified };
std::string_view reference_failure_name(ReferenceFailure failure);

//! One perturbed run: the truth to simulate and what the fusion is told.
struct PerturbedRun {
  Family family = Family::kFaultInSlew;
  std::string label;             //!< one line naming every draw (for a failure report)
  std::string case_name;         //!< the family's case of this run (fault kind, reference failure, ...)
  Scenario scenario;             //!< truth: motion, unit, reference (with its failure), drops, jitter
  SimOptions options;            //!< simulator seed and the gyro faults injected
  Calibration calibration;       //!< what the fusion is given (the truth unit unless the family perturbs it)
  double sample_period_s = 0.0;  //!< [s] the fusion's configured sample period; 0: from the data
  double max_angular_acceleration_dps2 = 0.0;  //!< [deg/s²] the fusion's bound; 0: its default
  double gap_from_s = 0.0;                     //!< [s] epochs in [gap_from_s, gap_until_s) are not delivered
  double gap_until_s = 0.0;                    //!< [s]
  ReferenceFailure reference_failure = ReferenceFailure::kNone;
  double reference_fault_at_s = -1.0;  //!< [s] when the reference failure begins (-1: none or from the start)
  double stated_sigma_multiple = 0.0;  //!< calibration family: the errors' size in stated 1σ (≤ 2)
};

//! The seed's as-built unit with n = 3…6 gyros: its first three (3), as is (4), or with gyros 5 and 6 added.
Calibration unit_with_gyros(int n);

//! `truth` as a calibration would state it: each scale factor off by `errors`·σ_s (alternating sign) and each
//! axis off by a perpendicular error whose largest component is `errors`·σ_h (direction from `seed`), with
//! `sigma:` stating σ_s (relative) and σ_h per component.
Calibration stated_calibration(const Calibration& truth, double errors, double scale_sigma, double axis_sigma,
                               std::uint64_t seed);

//! The run `index` of `family` under `seed` (docs/fdi_validation.md lists each family's draws).
PerturbedRun perturbed_run(Family family, std::uint64_t seed, std::uint64_t index);

//! The same run with its perturbation removed: same motion, unit, seed (so the same noise samples), no gyro
//! fault, no drop, jitter or gap, a healthy reference at the stated 1σ, the fusion given the true unit. What
//! the twin's sigma does is the fusion's fault-free character; what differs is the perturbation's doing.
PerturbedRun unperturbed_twin(const PerturbedRun& run);

}  // namespace tetra::sim
