#pragma once
// Fault-injection campaigns (`tetra campaign SPEC.yaml`, docs/campaign.md): a matrix of closed-loop
// scenarios × fault kinds × gyros × onset times × sizes × seeds, each case one closed-loop run with
// the fusion pipeline in process, each run one row of results.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/sim/fault.hpp"
#include "tetra/sim/fdi_verdict.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::sim {

struct CampaignSpec {
  std::vector<std::string> scenario_paths;  //!< closed-loop scenario files (resolved against the spec)
  std::vector<Scenario> scenarios;          //!< read from them
  std::vector<FaultKind> kinds;
  std::vector<int> gyros;                                        //!< 1..N
  std::vector<double> onsets_s;                                  //!< [s]
  std::vector<std::pair<FaultKind, std::vector<double>>> sizes;  //!< per kind that takes a size
  std::vector<std::uint64_t> seeds;
  std::optional<double> duration_s;  //!< overrides the scenarios' duration
  bool fault_free = false;           //!< also one fault-free run per scenario and seed (false alarms)
  fdi::PipelineConfig pipeline;      //!< the `pipeline:` map of the spec (defaults otherwise)
};

//! Reads a campaign spec; errors name file, line and key.
Result<CampaignSpec> read_campaign_spec(const std::string& path);

//! One case of the matrix. No fault: a fault-free run.
struct CampaignCase {
  std::size_t index = 0;           //!< position in the matrix (the run id)
  std::size_t scenario = 0;        //!< index into spec.scenarios
  std::optional<FaultSpec> fault;  //!< the injected fault
  std::uint64_t seed = 1;
};

//! The cases in a fixed order (scenario, kind, gyro, onset, size, seed; fault-free runs first).
std::vector<CampaignCase> expand_campaign(const CampaignSpec& spec);

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
  double final_knowledge_error_deg = 0.0;
  double final_sigma_deg = 0.0;
  double pointing_max_before_deg = 0.0;
  double pointing_rms_after_deg = 0.0;
  double pointing_max_after_deg = 0.0;
  std::optional<double> recover_s;
  double bound_deg = 0.0;
  double max_wheel_momentum_fraction = 0.0;
};

//! Runs one case to its row.
Result<CampaignRow> run_campaign_case(const CampaignSpec& spec, const CampaignCase& c);

//! The CSV header and one row (the columns: docs/campaign.md).
std::string campaign_csv_header();
std::string campaign_csv_row(const CampaignRow& row);
//! Parses a row written by campaign_csv_row (for resuming and the report); error on a torn line.
Result<CampaignRow> parse_campaign_row(const std::string& line);

//! [s] expected CUSUM detection delay of a bias step `size_dps` on gyro `gyro` (1..N) for the
//! pipeline's thresholds (k, h from the configuration and the calibration; fdi/detectors.hpp).
std::optional<double> cusum_theory_delay_s(const Calibration& unit, const fdi::PipelineConfig& config,
                                           double rate_hz, int gyro, double size_dps);

}  // namespace tetra::sim
