// One campaign case to its row: the run (closed or open loop) with the estimator a factory makes.
#include <cmath>
#include <filesystem>
#include <limits>

#include <yaml-cpp/yaml.h>

#include "tetra/core/units.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/open_loop_run.hpp"
#include "tetra/sim/pointing_report.hpp"

namespace tetra::sim {

namespace {

//! The columns that describe the case.
CampaignRow case_columns(const CampaignSpec& spec, const CampaignCase& c) {
  CampaignRow row;
  row.run = c.index;
  row.scenario = std::filesystem::path(spec.scenario_paths[c.scenario]).filename().string();
  row.kind = c.fault ? std::string(fault_kind_name(c.fault->kind)) : "none";
  row.gyro = c.fault ? c.fault->gyro : 0;
  row.onset_s = c.fault ? c.fault->at_s : 0.0;
  row.size = c.fault ? c.fault->size : 0.0;
  row.seed = c.seed;
  if (!spec.dispersions.empty())
    row.draws = dispersion_fields(spec.dispersions, c.draws, spec.max_gyro_count(), spec.kinds);
  return row;
}

//! The columns that describe the case and the CUSUM theory for bias steps.
CampaignRow case_row(const CampaignSpec& spec, const CampaignCase& c, const Scenario& sc) {
  CampaignRow row = case_columns(spec, c);
  if (c.fault && c.fault->kind == FaultKind::kBias) {  // the pipeline's thresholds: its calibration
    row.theory_delay_s = cusum_theory_delay_s(spec.scenarios[c.scenario].unit, spec.pipeline, sc.rate_hz,
                                              c.fault->gyro, c.fault->size);
  }
  return row;
}

//! The scenario the estimator is made for: the run's, with the calibration the pipeline uses (the
//! nominal unit) in place of the dispersed truth.
Scenario pipeline_view(const CampaignSpec& spec, const CampaignCase& c, Scenario sc) {
  sc.unit = spec.scenarios[c.scenario].unit;
  return sc;
}

SimOptions case_options(const CampaignCase& c) {
  SimOptions options;
  options.seed = c.seed;
  if (c.fault) options.faults.push_back(*c.fault);
  return options;
}

Result<CampaignRow> run_closed(const CampaignSpec& spec, const CampaignCase& c, const Scenario& sc,
                               const EstimatorFactory& make, Interrupt* interrupt) {
  auto simulator = ClosedLoopSimulator::create(sc, case_options(c));
  if (!simulator) return simulator.error();
  auto estimator = make(pipeline_view(spec, c, sc), c, simulator->initial_q_NB());
  if (!estimator) return estimator.error();
  auto record = run_closed_loop(*simulator, **estimator, interrupt);
  if (!record) return record.error();
  const PointingSummary summary = summarize(*record, *simulator);
  CampaignRow row = case_row(spec, c, sc);
  row.fdi = summary.fdi;
  row.final_knowledge_error_deg = summary.final_knowledge_error_deg;
  row.final_sigma_deg = summary.final_sigma_deg;
  row.pointing_max_before_deg = summary.segments.front().max_deg;
  const PointingSegment& after = summary.segments.back();
  row.pointing_rms_after_deg = after.rms_deg;
  row.pointing_max_after_deg = after.max_deg;
  // Recovered: every segment ends within the bound (a run that tumbles before its fault is not).
  row.recover_s = summary.within_bound_after_recovery ? after.recover_s : std::nullopt;
  row.bound_deg = summary.bound_deg;
  row.max_wheel_momentum_fraction = summary.max_wheel_momentum_fraction;
  return row;
}

Result<CampaignRow> run_open(const CampaignSpec& spec, const CampaignCase& c, const Scenario& sc,
                             const EstimatorFactory& make, Interrupt* interrupt) {
  const SimOptions options = case_options(c);
  auto simulator = Simulator::create(sc, options);
  if (!simulator) return simulator.error();
  auto estimator = make(pipeline_view(spec, c, sc), c, open_loop_initial_q_RB(*simulator));
  if (!estimator) return estimator.error();
  auto record = run_open_loop(*simulator, **estimator, interrupt);
  if (!record) return record.error();
  CampaignRow row = case_row(spec, c, sc);
  row.fdi = judge_fdi(record->events, all_faults(sc, options), sc.duration_s);
  row.final_knowledge_error_deg = record->final_knowledge_error_deg;
  row.final_sigma_deg = record->final_sigma_deg;
  for (double* pointing : {&row.pointing_max_before_deg, &row.pointing_rms_after_deg,
                           &row.pointing_max_after_deg, &row.bound_deg, &row.max_wheel_momentum_fraction})
    *pointing = kNaN;
  row.recover_s = std::nullopt;
  return row;
}

}  // namespace

CampaignRow campaign_error_row(const CampaignSpec& spec, std::size_t index, const std::string& message) {
  CampaignRow row = case_columns(spec, campaign_case(spec, index));
  row.error = message.empty() ? "unknown error" : message;
  for (char& ch : row.error) {
    if (ch == ',') ch = ';';
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  return row;
}

Scenario campaign_scenario(const CampaignSpec& spec, const CampaignCase& c) {
  Scenario sc = spec.scenarios[c.scenario];
  if (spec.duration_s) sc.duration_s = *spec.duration_s;
  sc.faults.clear();
  return c.draws.empty() ? sc : dispersed_scenario(sc, spec.dispersions, c.draws);
}

EstimatorFactory in_process_estimators(const CampaignSpec& spec) {
  return [config = spec.pipeline](const Scenario& sc, const CampaignCase&,
                                  const Quaternion& initial_q_RB) -> Result<std::unique_ptr<Estimator>> {
    auto estimator = PipelineEstimator::create(sc.unit, config, initial_q_RB);
    if (!estimator)
      return bad_input("the fusion pipeline cannot run this unit: " + describe(estimator.error()));
    return std::unique_ptr<Estimator>(std::make_unique<PipelineEstimator>(std::move(estimator.value())));
  };
}

Result<CampaignRow> run_campaign_case(const CampaignSpec& spec, const CampaignCase& c,
                                      const EstimatorFactory& make, Interrupt* interrupt) {
  const Scenario sc = campaign_scenario(spec, c);
  return spec.loop == CampaignLoop::kClosed ? run_closed(spec, c, sc, make, interrupt)
                                            : run_open(spec, c, sc, make, interrupt);
}

Result<CampaignRow> run_campaign_case(const CampaignSpec& spec, const CampaignCase& c) {
  return run_campaign_case(spec, c, in_process_estimators(spec));
}

CampaignRow campaign_run_row(const CampaignSpec& spec, std::size_t index, const EstimatorFactory& make,
                             Interrupt* interrupt) {
  try {
    auto row = run_campaign_case(spec, campaign_case(spec, index), make, interrupt);
    return row ? *row : campaign_error_row(spec, index, describe(row.error()));
  } catch (const std::exception& e) {
    return campaign_error_row(spec, index, std::string("exception: ") + e.what());
  } catch (...) {
    return campaign_error_row(spec, index, "unknown exception");
  }
}

std::string pipeline_yaml_from(const CampaignSpec& spec, const Quaternion& initial_q_RB) {
  YAML::Node map = YAML::Load(spec.pipeline_yaml);
  if (!map.IsMap()) map = YAML::Node(YAML::NodeType::Map);
  map["initial_q_wxyz"] =
      std::vector<double>{initial_q_RB.w(), initial_q_RB.x(), initial_q_RB.y(), initial_q_RB.z()};
  YAML::Emitter out;
  out.SetDoublePrecision(std::numeric_limits<double>::max_digits10);
  out << map;
  return out.c_str();
}

}  // namespace tetra::sim
