#pragma once
// Fault injection (docs/interfaces.md §2.7): "gyro=N,kind=K,at=SECONDS[,size=X][,until=SECONDS]".
//
// A fault is active on the epochs whose time t (the time written in the log) satisfies
// at ≤ t < until (no until: to the end). It is the last stage of the gyro model, applied to the
// output in volts of gyro N, in the order the faults were given:
//   bias     + s·size                 size [deg/s]
//   ramp     + s·size·(t − at)        size [deg/s²]
//   scale    + size·(v − β)           size relative (0.05 = +5 % scale factor)
//   noise    + (size − 1)·s·n_k       size multiplies the white-noise σ: n_k is the same white-noise
//                                     sample the gyro drew this epoch, so the white noise becomes size·n_k
//   spike    + s·size on the first epoch at or after `at` only (a spike has no `until`)
//   stuck    holds the last output the gyro delivered before `at`
//   zero     0 V
//   dropout  no sample (empty cell)
//   invalid  NaN
// Sizes are required where they mean something (bias, ramp, scale, noise, spike) and rejected elsewhere.

#include <optional>
#include <string>
#include <string_view>

#include "tetra/core/result.hpp"

namespace tetra::sim {

enum class FaultKind { kBias, kRamp, kScale, kStuck, kZero, kNoise, kSpike, kDropout, kInvalid };

struct FaultSpec {
  int gyro = 1;  //!< 1..N
  FaultKind kind = FaultKind::kBias;
  double at_s = 0.0;              //!< [s] start (inclusive)
  std::optional<double> until_s;  //!< [s] end (exclusive); none = to the end of the run
  double size = 0.0;              //!< unit depends on kind (see above)
};

//! Parses a fault spec; errors name the offending field.
Result<FaultSpec> parse_fault_spec(std::string_view text);
//! Text form accepted by parse_fault_spec.
std::string format_fault_spec(const FaultSpec& fault);
std::string_view fault_kind_name(FaultKind kind);
std::optional<FaultKind> fault_kind_from_name(std::string_view name);
//! True for the kinds that need a size (bias, ramp, scale, noise, spike).
bool kind_takes_size(FaultKind kind);
//! [kind's unit] largest |size| of any kind (1e6 deg/s is far beyond any gyro's range).
inline constexpr double kMaxFaultSize = 1.0e6;
//! A size in its kind's range: finite, |size| ≤ kMaxFaultSize, a noise multiplier ≥ 0, a scale change
//! above −1. The message reads after the size's name.
Status check_fault_size(FaultKind kind, double size);

//! True where the fault is active at time `t_s`.
inline bool fault_active(const FaultSpec& fault, double t_s) {
  return t_s >= fault.at_s && (!fault.until_s || t_s < *fault.until_s);
}

}  // namespace tetra::sim
