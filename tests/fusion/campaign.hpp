#pragma once
// Acceptance campaign helpers: run the simulator (sim/) straight into the pipeline, one epoch at a time, and
// record what the pipeline said and how far its attitude is from the truth.

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "tetra/core/units.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/sim/simulator.hpp"
#include "units.hpp"  // test::unit_with: the seed unit with N = 3..6 gyros

namespace tetra::test {

struct CampaignRun {
  std::vector<fdi::FdiEvent> events;
  std::optional<double> first_detected_s;  //!< [s] log time of the first `detected`
  std::optional<double> first_isolated_s;
  std::optional<int> isolated_gyro;
  fdi::FaultKind isolated_kind = fdi::FaultKind::kNone;
  bool unisolated = false;
  fdi::Mode final_mode = fdi::Mode::kNominal;
  double angle_y_deg = 0.0;                           //!< Σ wy_dps·Δt (the seed's "angle")
  std::vector<double> time_s;                         //!< per accepted epoch (when `keep_errors`)
  std::vector<Eigen::Vector3d> error_rad;             //!< log(q_true* ⊗ q_est) per accepted epoch
  std::vector<Eigen::Vector3d> sigma_rad;             //!< the published 1σ per body axis, per accepted epoch
  std::vector<Eigen::Vector3d> protection_level_rad;  //!< the published protection level, per accepted epoch
  std::vector<fdi::Mode> mode;                        //!< the published mode, per accepted epoch
  std::vector<GyroMask> delivered;  //!< the gyros whose sample was delivered and finite, per accepted epoch
  double final_sigma_deg = 0.0;
  double final_error_deg = 0.0;
};

struct CampaignOptions {
  bool keep_errors = false;
  std::optional<int> exclude_from_start;  //!< operator exclusion before the first epoch
  double stop_after_s = 1e300;            //!< [s] stop the run early (log time)
  double gap_from_s = 0.0;                //!< [s] epochs in [gap_from_s, gap_until_s) are not delivered
  double gap_until_s = 0.0;
};

inline CampaignRun run_campaign(const sim::Scenario& scenario, const sim::SimOptions& sim_options,
                                const Calibration& calibration, fdi::PipelineConfig config,
                                const CampaignOptions& options = {}) {
  CampaignRun run;
  auto simulator = sim::Simulator::create(scenario, sim_options);
  if (!simulator) {
    run.events.push_back(fdi::FdiEvent{});
    run.events.back().detail = "simulator: " + simulator.error().message;
    return run;
  }
  sim::SimEpoch se;
  if (!simulator->next(se)) return run;
  config.initial_q_RB = se.truth_q_RB;  // start from the true attitude
  auto pipeline = fdi::Pipeline::create(calibration, config);
  if (!pipeline) {
    run.events.push_back(fdi::FdiEvent{});
    run.events.back().detail = "pipeline: " + pipeline.error().message;
    return run;
  }
  if (options.exclude_from_start) (void)pipeline->exclude(*options.exclude_from_start, se.stamp_ns);
  fdi::Epoch e;
  double last_t = se.time_s;
  bool first = true;
  do {
    if (se.time_s > options.stop_after_s) break;
    if (se.time_s >= options.gap_from_s && se.time_s < options.gap_until_s) continue;
    e.stamp_ns = se.stamp_ns;
    e.raw = se.raw_V;
    e.present = se.present;
    e.reference_q_RB = se.reference_q_RB;
    const auto& r = pipeline->step(e);
    for (const auto& ev : r.events) {
      if (ev.type == fdi::EventType::kCommand) continue;  // operator acknowledgements are not FDI results
      run.events.push_back(ev);
      const double t = ns_to_seconds(ev.stamp_ns);
      if (ev.type == fdi::EventType::kDetected && !run.first_detected_s) run.first_detected_s = t;
      if (ev.type == fdi::EventType::kUnisolated) run.unisolated = true;
      if (ev.type == fdi::EventType::kIsolated && !run.first_isolated_s) {
        run.first_isolated_s = t;
        run.isolated_gyro = ev.gyro;
        run.isolated_kind = ev.kind;
      }
    }
    if (!r.accepted) continue;
    if (!first) run.angle_y_deg += r.attitude.omega_BR_B_rad_s.y() * kRadToDeg * (se.time_s - last_t);
    first = false;
    last_t = se.time_s;
    run.final_mode = r.attitude.mode;
    if (options.keep_errors) {
      run.time_s.push_back(se.time_s);
      run.error_rad.push_back(quat_log(se.truth_q_RB.conjugate() * r.attitude.q_RB));
      run.sigma_rad.push_back(r.attitude.sigma_rad);
      run.protection_level_rad.push_back(r.attitude.protection_level_rad);
      run.mode.push_back(r.attitude.mode);
      GyroMask delivered = 0;
      for (std::size_t i = 0; i < se.present.size(); ++i)
        if (se.present[i] != 0 && std::isfinite(se.raw_V[i])) delivered |= GyroMask{1} << i;
      run.delivered.push_back(delivered);
    }
    run.final_sigma_deg = r.attitude.sigma_rad.norm() * kRadToDeg;
    run.final_error_deg = angle_between(se.truth_q_RB, r.attitude.q_RB) * kRadToDeg;
  } while (simulator->next(se));
  return run;
}

//! A fault of `kind` on `gyro` from `at` [s] on, of `size` (its unit depends on the kind).
inline sim::FaultSpec fault(int gyro, sim::FaultKind kind, double at, double size = 0.0) {
  sim::FaultSpec f;
  f.gyro = gyro;
  f.kind = kind;
  f.at_s = at;
  f.size = size;
  return f;
}

inline std::string describe(const CampaignRun& run, int n_gyros = 4) {
  std::string s;
  for (const auto& e : run.events) s += fdi::to_json(e, n_gyros) + "\n";
  return s;
}

}  // namespace tetra::test
