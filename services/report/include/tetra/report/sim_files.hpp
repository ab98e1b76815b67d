#pragma once
// Simulated gyro data with known truth as `tetra sim` writes it (docs/sim.md): a built-in scenario or a
// scenario file, with the run's overrides, faults and unit, into a log file and a truth file; the turntable
// scenario into a turntable log; the simulated unit as a calibration file.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "tetra/core/calibration.hpp"
#include "tetra/core/result.hpp"
#include "tetra/report/argument_names.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"
#include "tetra/sim/turntable.hpp"

namespace tetra::report {

//! Values of a run that override the scenario's; each unset leaves the scenario's.
struct ScenarioOverrides {
  std::optional<double> rate_hz;                         //!< [Hz] gyro sampling rate
  std::optional<double> duration_min;                    //!< [min] duration (not for the turntable)
  std::optional<double> latitude_deg;                    //!< [deg] geodetic latitude
  std::optional<double> reference_hz;                    //!< [Hz] attitude reference rate (0 = none)
  std::optional<double> reference_noise_arcsec;          //!< [arcsec] reference 1σ per axis
  std::optional<double> reference_latency_s;             //!< [s] reference failure: latency
  std::optional<std::array<double, 3>> reference_bias;   //!< reference failure: [arcsec], at [s], ramp [s]
  std::optional<std::array<double, 3>> reference_misid;  //!< reference failure: [deg], at [s], duration [s]
  std::optional<double> acs_amplitude_deg;               //!< [deg] attitude-control motion amplitude
  std::optional<double> acs_accel_dps2;                  //!< [deg/s²] its peak acceleration
  std::optional<double> orbit_period_min;                //!< [min] orbit period
  std::optional<double> jitter_s;                        //!< [s] sample-time jitter, uniform ±
  std::optional<double> drop_probability;                //!< probability that a sample is not delivered
  std::optional<double> range_dps;                       //!< [deg/s] measuring range (saturation)
};

struct SimRunOptions {
  std::string scenario;             //!< turntable, static, lab-orbit, orbit, slews, or a scenario YAML file
  std::uint64_t seed = 1;           //!< the same seed gives byte-identical output
  std::string unit_path;            //!< calibration YAML of the simulated unit; empty: the seed paper's unit
  std::string out_path;             //!< log to write ("-": standard output); turntable: default "-"
  std::string truth_path;           //!< truth to write; empty: none (never for the turntable)
  std::vector<std::string> faults;  //!< fault specs replacing the scenario's (docs/interfaces.md §2.7)
  std::vector<std::string> added_faults;  //!< fault specs added to the scenario's (and to `faults`)
  ScenarioOverrides overrides;
  sim::TurntablePlan plan;  //!< the turntable scenario's plan
  //! The plan's arguments given (table_rate_dps, revolutions, order, wrap_angles): refused for any other
  //! scenario.
  std::vector<std::string> plan_given;
  bool closed_loop = false;  //!< a closed loop is run (elsewhere): out_path and truth_path do not apply
  void (*progress)(double fraction) = nullptr;  //!< called during runs of more than 2 000 000 epochs
  //! How messages name the arguments (out_path, duration_min, ..., as ScenarioOverrides' members) and the
  //! command ("command").
  ArgumentNames names;
};

//! Error::subject of a run without out_path ("missing_out") and of out_path or truth_path given with
//! closed_loop ("closed_loop").
inline constexpr const char* kSubjectMissingOut = "missing_out";
inline constexpr const char* kSubjectClosedLoop = "closed_loop";

//! The scenario (with the unit and the overrides) and the simulator's options (seed, faults) of a run.
struct PreparedSimulation {
  sim::Scenario scenario;
  sim::SimOptions options;
};

//! The scenario and options of a run other than the turntable (for a closed loop or a DDS publisher).
Result<PreparedSimulation> prepare_simulation(const SimRunOptions& options);

struct SimulatedFiles {
  std::string scenario;    //!< the scenario's name
  std::size_t epochs = 0;  //!< epochs simulated (turntable: rows)
  int gyros = 0;
};

//! Simulates the run into its files (all or none: through the output layer); one line on `err` says what
//! was written.
Result<SimulatedFiles> simulate_to_files(const SimRunOptions& options, std::ostream& err);

//! The unit a run would simulate (`unit_path`'s, else the seed paper's as-built unit) written as a
//! calibration file to `out_path`; one line on `err`. Returns the unit.
Result<Calibration> write_simulated_unit(const std::string& unit_path, const std::string& out_path,
                                         const ArgumentNames& names, std::ostream& err);

}  // namespace tetra::report
