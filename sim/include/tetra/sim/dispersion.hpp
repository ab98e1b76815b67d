#pragma once
// Dispersions of a campaign (docs/campaign.md, "Dispersions"): per parameter a distribution, drawn for
// every run as a pure function of (the campaign's dispersion seed, the run's index) — one seeded engine
// per (seed, run, parameter), never shared state — and applied to the run's true unit (against the
// calibration the pipeline keeps), spacecraft, star tracker, data path and fault.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/scenario.hpp"

namespace YAML {
class Node;
}

namespace tetra {
class YamlReader;
}

namespace tetra::sim {

enum class DistributionKind {
  kNormal,           //!< {normal: [mean, sigma]}
  kUniform,          //!< {uniform: [min, max]}
  kTruncatedNormal,  //!< {truncated_normal: [mean, sigma, min, max]}
  kLogUniform,       //!< {log_uniform: [min, max]}, 0 < min
  kCalibration,      //!< calibration, or {calibration: k}: normal, k (default 1) × the calibration's 1σ
  kChoice,           //!< {choice: [a, b, ...]}: one of the values, each equally likely
};

struct Distribution {
  DistributionKind kind = DistributionKind::kNormal;
  double mean = 0.0;   //!< normal, truncated normal
  double sigma = 0.0;  //!< normal, truncated normal; calibration: the multiple k of the 1σ
  double min = -std::numeric_limits<double>::infinity();  //!< the support (infinite for normal)
  double max = std::numeric_limits<double>::infinity();
  std::vector<double> choices;  //!< choice (fault.kind: indices into the spec's kinds)
};

//! What a dispersion applies to; the names in the spec are those of dispersion_parameter_name.
enum class DispersedParameter {
  kScaleFactorPpm,         //!< unit.scale_factor_ppm, per gyro: true s = s_cal·(1 + δ·1e-6)
  kBiasV,                  //!< unit.bias_V, per gyro: true β = β_cal + δ [V]
  kAxis,                   //!< unit.axis, per gyro and component: true h = (h_cal + δ)/|h_cal + δ|
  kArwFactor,              //!< unit.arw_factor, per gyro: true N = N_cal·δ
  kBiasInstabilityFactor,  //!< unit.bias_instability_factor, per gyro: true B = B_cal·δ
  kRateRandomWalkFactor,   //!< unit.rate_random_walk_factor, per gyro: true K = K_cal·δ
  kQuantizationFactor,     //!< unit.quantization_factor, per gyro: true Q = Q_cal·δ
  kInertiaPercent,  //!< spacecraft.inertia_percent, per body axis: I ← S·I·S, S = diag(√(1 + δ/100))
  kInertiaAxesDeg,  //!< spacecraft.inertia_axes_deg, a rotation vector [deg]: I ← R·I·Rᵀ
  kDisturbanceConstantNm,     //!< disturbance.constant_Nm, per body axis: + δ [N·m]
  kDisturbancePeriodicNm,     //!< disturbance.periodic_Nm, per body axis: + δ [N·m]
  kReferenceNoiseArcsec,      //!< reference.noise_arcsec: the value [arcsec]
  kReferenceBiasArcsec,       //!< reference.bias_arcsec: the value [arcsec] (from t = 0, a step)
  kReferenceLatencyS,         //!< reference.latency_s: the value [s]
  kReferenceDropProbability,  //!< reference.drop_probability: the value (star-tracker dropouts)
  kDropProbability,           //!< data.drop_probability: the value
  kJitterS,                   //!< data.jitter_s: the value [s] (open loop)
  kFaultOnsetS,               //!< fault.onset_s: + δ [s] to the case's onset
  kFaultSizeFactor,           //!< fault.size_factor: the case's size × δ
  kFaultGyro,                 //!< fault.gyro: the gyro (choice)
  kFaultKind,                 //!< fault.kind: the kind (choice), with its first size in `sizes:`
  // Appended (an engine's seed follows the parameter's place here: the ones above keep their draws).
  kThermalBiasDpsPerK,  //!< thermal.bias_dps_per_K, per gyro: the warm-up's coefficient c_i [deg/s/K]
  kThermalStartC,       //!< thermal.start_C: the unit's temperature at t = 0 [°C] (thermal.hpp)
  kRateRampDps2,        //!< unit.rate_ramp_dps2, per gyro: the true rate ramp R [deg/s²], stated or not
};

struct Dispersion {
  DispersedParameter parameter = DispersedParameter::kScaleFactorPpm;
  Distribution distribution;
};

struct DispersionSpec {
  std::uint64_t seed = 0;              //!< the campaign's dispersion seed
  std::vector<Dispersion> parameters;  //!< in the spec's order (the rows' columns follow it)
  bool empty() const { return parameters.empty(); }
};

//! The spec's name of a parameter ("unit.scale_factor_ppm").
std::string dispersion_parameter_name(DispersedParameter p);

//! Reads the `dispersions:` map (seed and parameters); errors name file, line and key. `kinds` are the
//! spec's kind names (fault.kind's choices must be among them), `gyros` its gyros (fault.gyro's too).
Result<DispersionSpec> parse_dispersions(const YamlReader& yaml, const YAML::Node& node,
                                         const std::vector<FaultKind>& kinds, const std::vector<int>& gyros);

//! One run's draws, one list per parameter of the spec (per gyro of `nominal`, per body axis, or one).
using DispersionDraws = std::vector<std::vector<double>>;

//! The draws of run `run`: a pure function of (spec.seed, run, parameter) and the nominal unit (the
//! calibration's 1σ).
DispersionDraws draw_dispersions(const DispersionSpec& spec, std::uint64_t run, const Calibration& nominal);

//! The scenario as the run's truth: unit, spacecraft, star tracker and data path dispersed.
Scenario dispersed_scenario(const Scenario& nominal, const DispersionSpec& spec,
                            const DispersionDraws& draws);
//! The sizes of the kinds that take one (the spec's `sizes:`).
using KindSizes = std::vector<std::pair<FaultKind, std::vector<double>>>;
//! The fault as the run's truth: onset, size, gyro and kind (a drawn kind with its first size in `sizes`).
FaultSpec dispersed_fault(const FaultSpec& fault, const DispersionSpec& spec, const DispersionDraws& draws,
                          const std::vector<FaultKind>& kinds, const KindSizes& sizes);

//! Checks the dispersions against one scenario as the campaign runs it (`name` in messages): every
//! draw's support keeps the run valid (onsets within the run, sizes in range, a reference to disperse,
//! the calibration's 1σ where asked). `node` is the `dispersions:` map.
Status check_dispersions(const YamlReader& yaml, const YAML::Node& node, const DispersionSpec& spec,
                         const Scenario& scenario, const std::string& name, bool closed_loop,
                         const std::vector<double>& onsets_s, const KindSizes& sizes);

//! The rows' column names for the draws (`gyros` the most gyros of any scenario) and one run's fields.
std::vector<std::string> dispersion_columns(const DispersionSpec& spec, int gyros);
std::vector<std::string> dispersion_fields(const DispersionSpec& spec, const DispersionDraws& draws,
                                           int gyros, const std::vector<FaultKind>& kinds);

}  // namespace tetra::sim
