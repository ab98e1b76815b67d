#include "tetra/sim/closed_loop_run.hpp"

#include <chrono>
#include <cmath>

#include "tetra/core/units.hpp"

namespace tetra::sim {

namespace {

constexpr double kRadPerSecToRpm = 60.0 / (2.0 * kPi);

AttitudeKnowledge knowledge_of(const fdi::AttitudeEstimate& e) {
  return {ns_to_seconds(e.stamp_ns), e.q_RB, e.omega_BR_B_rad_s, e.mode != fdi::Mode::kLost};
}

PointingSample record_epoch(const ClosedLoopSimulator& sim, const SimEpoch& epoch,
                            const std::optional<fdi::AttitudeEstimate>& latest) {
  PointingSample s;
  s.time_s = epoch.time_s;
  const PointingReference ref = sim.reference(epoch.time_s);
  s.error_deg = angle_between(ref.q_NR, epoch.truth_q_RB) * kRadToDeg;
  s.estimated_error_deg = kNaN;
  s.knowledge_error_deg = kNaN;
  s.sigma_deg = kNaN;
  s.estimate_age_s = kNaN;
  if (latest) {
    const double t_est = ns_to_seconds(latest->stamp_ns);
    s.estimated_error_deg = angle_between(sim.reference(t_est).q_NR, latest->q_RB) * kRadToDeg;
    s.knowledge_error_deg = angle_between(latest->q_RB, epoch.truth_q_RB) * kRadToDeg;
    if (latest->stamp_ns != epoch.stamp_ns) s.knowledge_error_deg = kNaN;  // not the same instant
    s.sigma_deg = latest->sigma_rad.maxCoeff() * kRadToDeg;
    s.estimate_age_s = epoch.time_s - t_est;
    s.mode = latest->mode;
    s.gyros = latest->gyros;
  }
  s.wheel_speed_rpm = sim.state().h_wheels_Nms / sim.spec().wheels.inertia_kg_m2 * kRadPerSecToRpm;
  return s;
}

}  // namespace

Result<PipelineEstimator> PipelineEstimator::create(const Calibration& unit, fdi::PipelineConfig config,
                                                    const Quaternion& initial_q_NB) {
  config.initial_q_RB = initial_q_NB;
  auto pipeline = fdi::Pipeline::create(unit, config);
  if (!pipeline) return pipeline.error();
  return PipelineEstimator(std::move(pipeline.value()));
}

Result<EstimatorOutput> PipelineEstimator::estimate(const SimEpoch& epoch) {
  input_.stamp_ns = epoch.stamp_ns;
  input_.raw = epoch.raw_V;
  input_.present = epoch.present;
  input_.reference_q_RB = epoch.reference_q_RB;
  const fdi::StepResult& step = pipeline_.step(input_);
  EstimatorOutput out;
  if (step.accepted) out.latest = step.attitude;
  out.events = step.events;
  return out;
}

Result<ClosedLoopRecord> run_closed_loop(ClosedLoopSimulator& simulator, Estimator& estimator,
                                         bool (*stop)()) {
  if (stop == nullptr) return run_closed_loop(simulator, estimator, static_cast<Interrupt*>(nullptr));
  Interrupt interrupt([stop](std::size_t, std::size_t) { return stop(); });
  return run_closed_loop(simulator, estimator, &interrupt);
}

Result<ClosedLoopRecord> run_closed_loop(ClosedLoopSimulator& simulator, Estimator& estimator,
                                         Interrupt* interrupt) {
  const auto start = std::chrono::steady_clock::now();
  ClosedLoopRecord record;
  record.series.reserve(simulator.epoch_count());
  std::optional<fdi::AttitudeEstimate> latest;
  const double h_max = simulator.spec().wheels.max_momentum_Nms;
  SimEpoch epoch;
  while (simulator.next(epoch)) {
    if (interrupt_requested(interrupt, simulator.epochs_done(), simulator.epoch_count()))
      return interrupted();
    auto out = estimator.estimate(epoch);
    if (!out) return out.error();
    if (out->latest) latest = out->latest;
    if (latest && latest->stamp_ns == epoch.stamp_ns) ++record.estimates_received;
    record.events.insert(record.events.end(), out->events.begin(), out->events.end());
    PointingSample sample = record_epoch(simulator, epoch, latest);
    std::optional<AttitudeKnowledge> knowledge;
    if (latest) knowledge = knowledge_of(*latest);
    const ControlOutput& control = simulator.control(knowledge);
    sample.control = control.state;
    sample.wheel_torque_Nm = control.tau_wheels_Nm;
    sample.torque_limited = control.torque_limited;
    sample.momentum_limited = control.momentum_limited;
    // A diverged state (within the ranges, a stiff case can still blow up) is a failure, never a number:
    // NaN would pass unseen through max() and be reported as a pointing error of 0.
    const BodyState& body = simulator.state();
    if (!std::isfinite(sample.error_deg) || !body.q_NB.coeffs().allFinite() ||
        !body.omega_BN_B_rad_s.allFinite() || !body.h_wheels_Nms.allFinite() ||
        !control.tau_wheels_Nm.allFinite()) {
      return failure(
          "closed loop: the spacecraft's state is not finite at t = " + std::to_string(epoch.time_s) +
          " s (the dynamics diverged: check inertia_kg_m2, the disturbances, the wheels and the "
          "controller gains against dynamics_hz)");
    }
    record.max_wheel_momentum_fraction =
        std::max(record.max_wheel_momentum_fraction, body.h_wheels_Nms.cwiseAbs().maxCoeff() / h_max);
    record.series.push_back(std::move(sample));
  }
  if (Status st = estimator.finish(record.events); !st) return st.error();
  record.counters = simulator.counters();
  record.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return record;
}

}  // namespace tetra::sim
