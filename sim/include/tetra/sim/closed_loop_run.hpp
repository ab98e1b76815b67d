#pragma once
// Running the closed loop: the closed-loop simulator, an attitude estimator (the fusion pipeline in
// process, or a service over DDS) and the record of what happened (pointing, wheels, FDI events).
//
// Per epoch k: the simulator makes epoch k's samples from its state at t_k; the estimator returns
// the latest attitude it has (in process and in lockstep: epoch k's own); the record takes the truth,
// the commanded attitude and that estimate at t_k; the controller computes its command and the
// dynamics advance to t_{k+1}.

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/interrupt.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/sim/closed_loop.hpp"

namespace tetra::sim {

//! What an estimator returns for one epoch.
struct EstimatorOutput {
  std::optional<fdi::AttitudeEstimate> latest;  //!< the newest estimate available (any epoch), none yet
  std::vector<fdi::FdiEvent> events;            //!< FDI events that came with it (may be empty)
};

class Estimator {
 public:
  virtual ~Estimator() = default;
  //! Takes epoch `epoch`'s samples; returns the latest estimate. Errors end the run.
  virtual Result<EstimatorOutput> estimate(const SimEpoch& epoch) = 0;
  //! The run is over: appends the FDI events not yet returned (an estimator over DDS receives them
  //! apart from the attitudes and waits here for the last ones). In process: nothing to add.
  virtual Status finish(std::vector<fdi::FdiEvent>& /*events*/) { return ok_status(); }
};

//! The fusion pipeline in process (with `exclusion_enabled: false` in its configuration it reports isolations
//! and keeps the gyros).
class PipelineEstimator final : public Estimator {
 public:
  //! `initial_q_NB`: the pipeline starts from the true initial attitude (as after star-tracker
  //! acquisition); the configuration's initial attitude is replaced.
  static Result<PipelineEstimator> create(const Calibration& unit, fdi::PipelineConfig config,
                                          const Quaternion& initial_q_NB);
  Result<EstimatorOutput> estimate(const SimEpoch& epoch) override;
  const fdi::Pipeline& pipeline() const { return pipeline_; }

 private:
  explicit PipelineEstimator(fdi::Pipeline pipeline) : pipeline_(std::move(pipeline)) {}
  fdi::Pipeline pipeline_;
  fdi::Epoch input_;
};

//! One epoch of the record.
struct PointingSample {
  double time_s = 0.0;               //!< [s]
  double error_deg = 0.0;            //!< [deg] true attitude vs commanded
  double estimated_error_deg = 0.0;  //!< [deg] estimate vs commanded (what the controller sees); NaN: none
  double knowledge_error_deg = 0.0;  //!< [deg] estimate vs truth; NaN: none
  double sigma_deg = 0.0;            //!< [deg] largest published 1σ; NaN: none
  double estimate_age_s = 0.0;       //!< [s] t_k − time of the estimate used; NaN: none
  fdi::Mode mode = fdi::Mode::kNominal;  //!< of the estimate used
  GyroMask gyros = 0;                    //!< gyros used by that estimate
  ControlState control = ControlState::kNormal;
  Eigen::VectorXd wheel_speed_rpm;  //!< [rpm] h_w / J_w per wheel
  Eigen::VectorXd wheel_torque_Nm;  //!< [N·m] commanded for the period that starts here
  bool torque_limited = false;
  bool momentum_limited = false;
};

struct ClosedLoopRecord {
  std::vector<PointingSample> series;
  std::vector<fdi::FdiEvent> events;
  bool fdi_events = true;  //!< false: the estimator's events were not seen (no FDI verdict)
  ControlCounters counters;
  std::uint64_t estimates_received = 0;      //!< epochs with an estimate of that very epoch
  double max_wheel_momentum_fraction = 0.0;  //!< largest |h_i| / h_max seen
  double wall_s = 0.0;                       //!< [s] wall-clock time of the run
};

//! Runs the loop to the end of the scenario. `stop` (optional) is polled every epoch.
Result<ClosedLoopRecord> run_closed_loop(ClosedLoopSimulator& simulator, Estimator& estimator,
                                         bool (*stop)() = nullptr);
//! The same with an Interrupt (optional), polled every epoch (epochs done of the run's): when it asks to
//! stop, the run returns interrupted().
Result<ClosedLoopRecord> run_closed_loop(ClosedLoopSimulator& simulator, Estimator& estimator,
                                         Interrupt* interrupt);

}  // namespace tetra::sim
