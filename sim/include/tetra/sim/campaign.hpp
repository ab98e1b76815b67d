#pragma once
// Fault-injection campaigns (`tetra campaign SPEC.yaml`, docs/campaign.md): a matrix of scenarios ×
// fault kinds × gyros × onset times × sizes × seeds, each case one run (closed loop: the controller
// steers with the estimate; open loop: the scenario's own motion, the estimate only scored), each run
// one row of results. The estimator is the fusion pipeline in process, or (made by the caller, e.g. a
// `tetra fusion` service over DDS) anything behind sim::Estimator.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/dispersion.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/fdi_verdict.hpp"
#include "tetra/sim/requirement.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::sim {

//! `loop:` what a run simulates.
enum class CampaignLoop {
  kClosed,  //!< the closed loop (the scenarios' closed_loop sections): pointing columns filled
  kOpen,    //!< the scenarios' open-loop motion: no controller, pointing columns empty
};

//! `target:` where the fusion pipeline runs.
enum class CampaignTarget {
  kInProcess,  //!< in the campaign's worker processes
  kDds,        //!< a `tetra fusion` service per run, over DDS in lockstep (tetra/campaign/dds_estimators.hpp)
};

struct CampaignSpec {
  std::vector<std::string> scenario_paths;  //!< scenario files or built-in names (resolved against the spec)
  std::vector<Scenario> scenarios;          //!< read from them
  std::vector<FaultKind> kinds;
  std::vector<int> gyros;                                        //!< 1..N
  std::vector<double> onsets_s;                                  //!< [s]
  std::vector<std::pair<FaultKind, std::vector<double>>> sizes;  //!< per kind that takes a size
  std::vector<std::uint64_t> seeds;
  std::optional<double> duration_s;  //!< overrides the scenarios' duration
  bool fault_free = false;           //!< also one fault-free run per scenario and seed (false alarms)
  fdi::PipelineConfig pipeline;      //!< the `pipeline:` map of the spec (defaults otherwise)
  std::string pipeline_yaml;  //!< that map as YAML text ("{}" without one), for a service's configuration
  CampaignLoop loop = CampaignLoop::kClosed;
  CampaignTarget target = CampaignTarget::kInProcess;
  int dds_domain = 0;                     //!< `domain:` the DDS domain id (target dds)
  DispersionSpec dispersions;             //!< `dispersions:` (none: every run the nominal truth)
  std::vector<Requirement> requirements;  //!< `requirements:` judged by the report
  //! The most gyros of any scenario (the rows' per-gyro dispersion columns).
  int max_gyro_count() const;
};

//! Reads a campaign spec; errors name file, line and key. Every value is checked (types, ranges,
//! duplicates, sizes only for the kinds run), the matrix's size is bounded (kMaxCampaignRuns) and
//! every case is known to be able to run (each scenario with the pipeline, each onset before the end,
//! each kind on each gyro) before anything runs.
Result<CampaignSpec> read_campaign_spec(const std::string& path);
//! The same from YAML text (e.g. a Python dict as JSON): `source` names it in messages, `base_dir` resolves
//! the scenario files it names.
Result<CampaignSpec> parse_campaign_spec(const std::string& yaml_text, const std::string& source,
                                         const std::string& base_dir);

//! One case of the matrix. No fault: a fault-free run.
struct CampaignCase {
  std::size_t index = 0;           //!< position in the matrix (the run id)
  std::size_t scenario = 0;        //!< index into spec.scenarios
  std::optional<FaultSpec> fault;  //!< the injected fault
  std::uint64_t seed = 1;
  DispersionDraws draws;  //!< the run's dispersion draws (empty without dispersions)
};

//! [runs] the largest campaign read (docs/campaign.md): a small spec can describe a matrix of any size.
inline constexpr std::size_t kMaxCampaignRuns = 1'000'000;
//! The number of runs: scenarios × (seeds if fault_free + Σ over kinds of gyros × onsets × sizes × seeds),
//! computed without overflow; an error naming the lists' lengths above kMaxCampaignRuns (or for none).
Result<std::size_t> campaign_run_count(const CampaignSpec& spec);
//! Case `index` (< campaign_run_count) of the fixed order (scenario, kind, gyro, onset, size, seed;
//! fault-free runs first), made on demand: a campaign never holds its cases in memory.
CampaignCase campaign_case(const CampaignSpec& spec, std::size_t index);

//! The scenario of a case as it runs: the spec's duration, the matrix's fault instead of its own, the
//! case's dispersions applied (its unit is then the true unit, not the calibration the pipeline uses).
Scenario campaign_scenario(const CampaignSpec& spec, const CampaignCase& c);

struct CampaignRow {
  std::size_t run = 0;
  std::string scenario;
  std::string kind;  //!< "none" for a fault-free run
  int gyro = 0;
  double onset_s = 0.0;
  double size = 0.0;
  std::uint64_t seed = 0;
  FdiVerdict fdi;
  std::optional<double> theory_delay_s;  //!< [s] CUSUM's expected detection delay (bias faults)
  // NaN (an empty CSV field): not available (no estimate; the pointing of an open-loop run).
  double final_knowledge_error_deg = 0.0;
  double final_sigma_deg = 0.0;
  double pointing_max_before_deg = 0.0;
  double pointing_rms_after_deg = 0.0;
  double pointing_max_after_deg = 0.0;
  std::optional<double> recover_s;
  double bound_deg = 0.0;
  double max_wheel_momentum_fraction = 0.0;
  std::vector<std::string> draws;  //!< the dispersion columns' fields (campaigns with dispersions)
  //! Empty for a run that finished; otherwise why it did not (an error value, an exception, a crashed
  //! or timed-out worker): the row then holds only the case's columns, `outcome` error, and this.
  std::string error;
};

//! Makes the estimator of one run from the scenario as it runs (its `unit` the calibration the pipeline
//! uses: the nominal unit, not a dispersed truth) and its true initial attitude.
using EstimatorFactory = std::function<Result<std::unique_ptr<Estimator>>(
    const Scenario& scenario, const CampaignCase& c, const Quaternion& initial_q_RB)>;
//! The fusion pipeline in process, with the spec's configuration.
EstimatorFactory in_process_estimators(const CampaignSpec& spec);

//! The row of a case that did not run to its end: the case's columns and `message` (a single line:
//! commas and line breaks become ';' and ' ', so the row stays one CSV line).
CampaignRow campaign_error_row(const CampaignSpec& spec, std::size_t index, const std::string& message);

//! Runs one case to its row, with the estimator `make` gives. `interrupt` (optional) is polled every
//! epoch of the run (epochs done of the run's): when it asks to stop, the case returns interrupted().
Result<CampaignRow> run_campaign_case(const CampaignSpec& spec, const CampaignCase& c,
                                      const EstimatorFactory& make, Interrupt* interrupt = nullptr);
//! Runs one case to its row with the pipeline in process.
Result<CampaignRow> run_campaign_case(const CampaignSpec& spec, const CampaignCase& c);
//! The row of run `index` whatever happens in it: its result, or an error row (campaign_error_row) with
//! the message of an error value or of an exception. A run its `interrupt` stopped is an error row
//! "interrupted" (the caller, who asked, knows to drop it).
CampaignRow campaign_run_row(const CampaignSpec& spec, std::size_t index, const EstimatorFactory& make,
                             Interrupt* interrupt = nullptr);

//! The spec's `pipeline:` map with `initial_q_wxyz` set to `initial_q_RB` (every digit kept), as YAML
//! text: a service configured with it starts where the in-process pipeline starts.
std::string pipeline_yaml_from(const CampaignSpec& spec, const Quaternion& initial_q_RB);

//! The CSV header and one row (the columns: docs/campaign.md); a spec with dispersions appends a
//! column per drawn value (dispersion_columns).
std::string campaign_csv_header();
std::string campaign_csv_header(const CampaignSpec& spec);
std::string campaign_csv_row(const CampaignRow& row);
//! Parses a row written by campaign_csv_row (for resuming and the report); error on a torn line.
Result<CampaignRow> parse_campaign_row(const std::string& line);
//! The same for a row under `header`: a row with fewer fields (torn among the dispersion columns) or
//! more is an error too.
Result<CampaignRow> parse_campaign_row(const std::string& line, const std::string& header);

//! A row read back (parse_campaign_row) checked against the spec's matrix: its run one of the matrix's, its
//! case columns (scenario, kind, gyro, onset, size, seed, the dispersion draws) that run's case, and for a
//! finished run its verdict as judge_fdi gives one (gyros 1..N of the scenario's unit, the outcome the
//! isolations and detections imply, each delay with its gyro), its times within the run and its columns
//! those of its kind and loop. Bad input "campaign row: FIELD 'value' (why)" for the first that is not.
Status check_campaign_row(const CampaignSpec& spec, const CampaignRow& row);

//! [s] expected CUSUM detection delay of a bias step `size_dps` on gyro `gyro` (1..N) for the
//! pipeline's thresholds (k, h from the configuration and the calibration; fdi/detectors.hpp).
std::optional<double> cusum_theory_delay_s(const Calibration& unit, const fdi::PipelineConfig& config,
                                           double rate_hz, int gyro, double size_dps);

}  // namespace tetra::sim
