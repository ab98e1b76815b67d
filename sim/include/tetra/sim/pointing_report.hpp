#pragma once
// Pointing outputs of a closed-loop run: the summary (RMS and max pointing error before and after
// each fault, time to recover, wheel saturation, FDI verdict) as JSON, and the time series as CSV.
//
// Segments: [0, first onset), then [onset_i, onset_{i+1}) for each distinct fault onset in the run.
// Time to recover in a segment: 0 when the pointing error never exceeds the bound in it; otherwise the
// time from the segment's start to the end of the last epoch above the bound, provided the segment ends
// below it (none = not recovered). The run is recovered when every segment is, the first one (no
// fault yet) included: a fault-free run that ends off the bound (a tumble) is not recovered.

#include <optional>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/sim/closed_loop.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/fdi_verdict.hpp"

namespace tetra::sim {

struct PointingSegment {
  std::string label;  //!< "before faults" or the fault spec whose onset starts it
  double from_s = 0.0;
  double to_s = 0.0;
  double rms_deg = 0.0;  //!< [deg] pointing error (truth vs commanded)
  double max_deg = 0.0;
  double estimated_rms_deg = 0.0;   //!< [deg] what the controller saw
  std::optional<double> recover_s;  //!< [s] see above
};

struct PointingSummary {
  double bound_deg = 0.0;
  std::vector<PointingSegment> segments;
  double rms_deg = 0.0;  //!< whole run
  double max_deg = 0.0;
  double final_error_deg = 0.0;
  double final_knowledge_error_deg = 0.0;  //!< [deg] estimate vs truth at the end (NaN: none)
  double final_sigma_deg = 0.0;            //!< [deg] published 1σ at the end (NaN: none)
  double max_wheel_momentum_fraction = 0.0;
  double torque_limited_s = 0.0;    //!< [s] time the commanded torque was scaled down
  double momentum_limited_s = 0.0;  //!< [s] time a wheel sat at its momentum limit
  ControlCounters counters;
  double mean_estimate_age_s = 0.0;  //!< [s] age of the estimate the controller used (epochs with one)
  double max_estimate_age_s = 0.0;   //!< [s]
  FdiVerdict fdi;
  bool within_bound_after_recovery = true;  //!< every segment recovered (JSON "recovered")
};

PointingSummary summarize(const ClosedLoopRecord& record, const ClosedLoopSimulator& simulator);
//! One JSON object (pretty, multi-line) with every field of the summary; "fdi": null without
//! `with_fdi` (the run's FDI events were not seen).
std::string summary_json(const PointingSummary& summary, bool with_fdi = true);
//! The series: time_s,error_deg,estimated_error_deg,knowledge_error_deg,sigma_deg,age_s,mode,gyros,
//! control,speed_rpm_1..n,torque_Nm_1..n (written through a temporary file renamed on success).
Status write_pointing_csv(const std::string& path, const ClosedLoopRecord& record, int n_gyros);

}  // namespace tetra::sim
