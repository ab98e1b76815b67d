#pragma once
// The closed-loop simulator: the spacecraft's dynamics (dynamics.hpp) instead of the closed-form
// motion, the same gyro package as the open-loop simulator (gyro_package.hpp), and the attitude
// controller (controller.hpp) fed with an attitude estimate from outside (the fusion pipeline, in
// process or over DDS). One epoch is:
//   next(epoch)     the gyro samples (and reference) at t_k from the current state
//   control(latest) the controller's wheel torques from the latest estimate, held while the
//                   dynamics are integrated with RK4 from t_k to t_{k+1} (dynamics_hz steps)
// Sample times are the nominal k/rate (the scenario's jitter does not apply in closed loop).
// Deterministic: the same scenario, seed and estimates give the same states bit for bit.

#include <cstdint>
#include <optional>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/sim/closed_loop_spec.hpp"
#include "tetra/sim/controller.hpp"
#include "tetra/sim/dynamics.hpp"
#include "tetra/sim/gyro_package.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::sim {

class ClosedLoopSimulator {
 public:
  //! The scenario must have a `closed_loop:` section.
  static Result<ClosedLoopSimulator> create(const Scenario& scenario, const SimOptions& options);

  //! The gyro samples of the next epoch; false at the end. Call control() before the next call.
  bool next(SimEpoch& out);
  //! Computes the control from `latest` and integrates to the next epoch.
  const ControlOutput& control(const std::optional<AttitudeKnowledge>& latest);

  const BodyState& state() const { return state_; }
  //! The commanded attitude at `t_s`.
  PointingReference reference(double t_s) const { return controller_.guidance().at(t_s); }
  //! True attitude at t = 0 (the fusion pipeline starts from it).
  const Quaternion& initial_q_NB() const { return initial_q_NB_; }
  const ControlCounters& counters() const { return controller_.counters(); }
  const Scenario& scenario() const { return scenario_; }
  const ClosedLoopSpec& spec() const { return *scenario_.closed_loop; }
  const std::vector<FaultSpec>& faults() const { return package_.faults(); }
  int gyro_count() const { return scenario_.unit.gyro_count(); }
  std::size_t epoch_count() const { return epochs_; }
  std::size_t epochs_done() const { return k_; }
  double time_s(std::size_t k) const;
  std::int64_t stamp_ns(std::size_t k) const;
  std::int64_t period_ns() const { return seconds_to_ns(1.0 / scenario_.rate_hz); }

 private:
  ClosedLoopSimulator(Scenario scenario, const SimOptions& options);

  Scenario scenario_;
  GyroPackage package_;
  Spacecraft spacecraft_;
  AttitudeController controller_;
  BodyState state_;
  Quaternion initial_q_NB_;
  ControlOutput last_control_;
  std::size_t epochs_ = 0;
  std::size_t k_ = 0;
  bool awaiting_control_ = false;
};

}  // namespace tetra::sim
