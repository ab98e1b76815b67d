#pragma once
// Scenarios: what is simulated (motion, duration, sampling, unit, gyro-model options, attitude
// reference, faults, sampling imperfections). Built-in by name, or read from a YAML file
// (format in docs/sim.md; unknown keys are an error, every error names file, line and key).

#include <optional>
#include <string>
#include <vector>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/result.hpp"
#include "tetra/sim/closed_loop_spec.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/gyro_model.hpp"
#include "tetra/sim/motion.hpp"
#include "tetra/sim/thermal.hpp"

namespace tetra::sim {

//! Star-tracker-like attitude reference: q_RB(t − latency) ⊗ exp(δθ + b(t) + m(t)), δθ ~ N(0, σ²·I) per axis
//! (in B); b a slow (thermal) bias, m a mis-identification episode. The failure modes (latency, slow bias,
//! mis-identification, dropouts; a noisier reference is `noise_arcsec` itself) are off by default
//! (docs/sim.md).
struct ReferenceOptions {
  double rate_hz = 0.0;       //!< [Hz] 0 = no reference
  double noise_arcsec = 0.0;  //!< [arcsec] 1σ per axis
  double latency_s = 0.0;     //!< [s] the sample shows the attitude this long before its time stamp
  double bias_arcsec = 0.0;   //!< [arcsec] slow bias about (1, 1, 1)/√3 of B, reached after bias_ramp_s
  double bias_at_s = 0.0;     //!< [s] the slow bias starts growing here
  double bias_ramp_s = 0.0;   //!< [s] it grows linearly to bias_arcsec over this long (0: a step)
  double misid_deg = 0.0;     //!< [deg] mis-identification: turned about (0.6, 0.8, 0) of B by this much...
  double misid_at_s = 0.0;    //!< [s] ...from here...
  double misid_duration_s = 0.0;  //!< [s] ...for this long (0: none)
  double drop_probability = 0.0;  //!< each reference sample independently not delivered (a dropout)
};

struct Scenario {
  std::string name = "static";                //!< built-in name or file name (metadata)
  MotionSpec motion;                          //!< truth motion
  double duration_s = 7200.0;                 //!< [s]
  double rate_hz = 10.0;                      //!< [Hz] gyro sampling rate
  Calibration unit = seed_as_built_unit();    //!< the as-built truth of the simulated unit
  GyroModelOptions model;                     //!< options the calibration file does not carry
  ReferenceOptions reference;                 //!< attitude reference (none by default)
  ThermalOptions thermal;                     //!< a warm-up's bias transient (none by default; thermal.hpp)
  std::vector<FaultSpec> faults;              //!< injected faults
  double jitter_s = 0.0;                      //!< [s] sample times uniform in nominal ± jitter (< period/2)
  double drop_probability = 0.0;              //!< each gyro sample independently not delivered
  std::optional<ClosedLoopSpec> closed_loop;  //!< closed loop: dynamics and control (closed_loop.hpp)
  std::vector<std::string> named_files;  //!< files it names, as read (its `unit:`): a campaign's identity
};

//! Ranges of a scenario's numbers besides the motion's (motion.hpp) and the closed loop's
//! (closed_loop_spec.hpp); docs/sim.md, "Ranges".
inline constexpr double kMaxDuration_s = 6.0e8;             //!< [s] 1e7 min (about 19 years)
inline constexpr double kMaxRate_hz = 1.0e5;                //!< [Hz] gyro sampling rate
inline constexpr double kMaxEpochs = 2.0e9;                 //!< duration_s × rate_hz
inline constexpr double kMaxReferenceNoise_arcsec = 3.6e4;  //!< [arcsec] 10 deg
inline constexpr double kMaxCorrelation_s = 1.0e9;          //!< [s] bias_instability_correlation_s
inline constexpr double kMaxRange_dps = 1.0e6;              //!< [deg/s] gyro_model range_dps

//! Names of the built-in scenarios (turntable is separate: see turntable.hpp).
std::vector<std::string> builtin_scenario_names();
//! A built-in scenario: static, lab-orbit, orbit, slews (defaults in docs/sim.md).
Result<Scenario> builtin_scenario(const std::string& name);
//! A scenario from YAML text; `source` names it in messages and `base_dir` resolves `unit:` paths. `unit`,
//! when given, replaces the file's (or the default) unit before the checks — a command's --unit — so what
//! depends on the unit (thermal coefficients, fault gyros) is judged against the unit the run will use.
Result<Scenario> parse_scenario(const std::string& yaml_text, const std::string& source,
                                const std::string& base_dir = ".", const Calibration* unit = nullptr);
Result<Scenario> read_scenario(const std::string& path, const Calibration* unit = nullptr);
//! Checks everything the simulator relies on (numbers, fault gyros exist, ...).
Status validate_scenario(const Scenario& scenario);

}  // namespace tetra::sim
