#include "tetra/sim/closed_loop.hpp"

#include <cmath>

#include "tetra/core/units.hpp"

namespace tetra::sim {

Result<ClosedLoopSimulator> ClosedLoopSimulator::create(const Scenario& scenario, const SimOptions& options) {
  if (!scenario.closed_loop) return bad_input(scenario.name + ": no closed_loop section");
  Scenario all = scenario;
  all.faults = all_faults(scenario, options);
  if (Status st = validate_scenario(all); !st) return st.error();
  if (scenario.jitter_s != 0.0) return bad_input(scenario.name + ": jitter_s does not apply in closed loop");
  return ClosedLoopSimulator(scenario, options);
}

ClosedLoopSimulator::ClosedLoopSimulator(Scenario scenario, const SimOptions& options)
    : scenario_(std::move(scenario)),
      package_(scenario_, all_faults(scenario_, options), options.seed),
      spacecraft_(*scenario_.closed_loop, scenario_.motion.orbit_period_s),
      controller_(*scenario_.closed_loop, spacecraft_.wheel_axes(), spacecraft_.orbit_rate_rad_s()) {
  const ClosedLoopSpec& spec = *scenario_.closed_loop;
  epochs_ = static_cast<std::size_t>(std::llround(scenario_.duration_s * scenario_.rate_hz));
  const PointingReference ref0 = controller_.guidance().at(0.0);
  const Quaternion q_RB0 = quat_exp(spec.initial_error_deg * kDegToRad);
  state_.q_NB = canonical(ref0.q_NR * q_RB0);
  state_.omega_BN_B_rad_s =
      q_RB0.conjugate() * ref0.omega_RN_R_rad_s + spec.initial_rate_error_dps * kDegToRad;
  state_.h_wheels_Nms = Eigen::VectorXd::Zero(spacecraft_.wheel_axes().cols());
  initial_q_NB_ = state_.q_NB;
  last_control_.tau_wheels_Nm = state_.h_wheels_Nms;
}

std::int64_t ClosedLoopSimulator::stamp_ns(std::size_t k) const {
  return static_cast<std::int64_t>(
      std::llround(static_cast<double>(k) * static_cast<double>(kNanosPerSecond) / scenario_.rate_hz));
}

double ClosedLoopSimulator::time_s(std::size_t k) const {
  return ns_to_seconds(stamp_ns(k));
}

bool ClosedLoopSimulator::next(SimEpoch& out) {
  if (k_ >= epochs_ || awaiting_control_) return false;
  out.stamp_ns = stamp_ns(k_);
  out.time_s = time_s(k_);
  out.truth_q_RB = state_.q_NB;
  out.truth_omega_BR_B_rad_s = state_.omega_BN_B_rad_s;
  out.omega_BN_B_rad_s = state_.omega_BN_B_rad_s;
  package_.sample(state_.omega_BN_B_rad_s * kRadToDeg, out.time_s, out.raw_V, out.present);
  out.reference_q_RB = package_.reference(k_, state_.q_NB);
  awaiting_control_ = true;
  return true;
}

const ControlOutput& ClosedLoopSimulator::control(const std::optional<AttitudeKnowledge>& latest) {
  if (!awaiting_control_) return last_control_;
  const double t0 = time_s(k_);
  const double t1 = time_s(k_ + 1);
  const double period_s = t1 - t0;
  last_control_ = controller_.command(t0, latest, state_.h_wheels_Nms, period_s);
  const double dynamics_hz = scenario_.closed_loop->dynamics_hz;
  const auto steps = std::max<long long>(1, std::llround(std::ceil(dynamics_hz * period_s - 1e-9)));
  const double h = period_s / static_cast<double>(steps);
  spacecraft_.advance(state_, last_control_.tau_wheels_Nm, t0, h, steps);
  ++k_;
  awaiting_control_ = false;
  return last_control_;
}

}  // namespace tetra::sim
