#include "tetra/sim/dynamics.hpp"

#include <cmath>

#include "tetra/core/units.hpp"

namespace tetra::sim {

namespace {

Quaternion quat_from(const Eigen::Vector4d& wxyz) {
  return Quaternion(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}

Eigen::Vector4d wxyz_of(const Quaternion& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace

Eigen::MatrixXd wheel_axes_B(const WheelSpec& wheels) {
  if (wheels.count == 3) return Eigen::MatrixXd::Identity(3, 3);
  Eigen::MatrixXd g(3, wheels.count);
  const double el = wheels.pyramid_elevation_deg * kDegToRad;
  for (int i = 0; i < wheels.count; ++i) {
    const double az = (45.0 + 90.0 * i) * kDegToRad;
    g.col(i) = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  }
  return g;
}

Quaternion orbit_frame_q_NO(double orbit_rate_rad_s, double t_s) {
  return quat_exp(Eigen::Vector3d(0.0, -orbit_rate_rad_s * t_s, 0.0));
}

Spacecraft::Spacecraft(const ClosedLoopSpec& spec, double orbit_period_s)
    : inertia_(spec.inertia_kg_m2),
      inertia_inv_(spec.inertia_kg_m2.inverse()),
      axes_B_(wheel_axes_B(spec.wheels)),
      disturbance_(spec.disturbance),
      orbit_rate_rad_s_(2.0 * kPi / orbit_period_s) {}

Spacecraft::TimeTerms Spacecraft::at_time(double t_s) const {
  const double n = orbit_rate_rad_s_;
  TimeTerms at;
  at.tau_B_Nm = disturbance_.constant_Nm + disturbance_.periodic_Nm * std::sin(n * t_s);
  // Zenith = −Z of the orbit frame; in B through N.
  if (disturbance_.gravity_gradient) at.zenith_N = orbit_frame_q_NO(n, t_s) * Eigen::Vector3d(0.0, 0.0, -1.0);
  return at;
}

Eigen::Vector3d Spacecraft::disturbance_B_Nm(const Quaternion& q_NB, const TimeTerms& at) const {
  const double n = orbit_rate_rad_s_;
  Eigen::Vector3d tau = at.tau_B_Nm;
  if (disturbance_.gravity_gradient) {
    const Eigen::Vector3d r_B = q_NB.conjugate() * at.zenith_N;
    tau += 3.0 * n * n * r_B.cross(inertia_ * r_B);
  }
  return tau;
}

namespace {

//! [in B] G·v over the wheels (`v` n values along their axes; `kWheels` > 0: n known at compile time), summed
//! as Eigen's general matrix-vector product sums a 3×n product (each row from 0, wheel by wheel): the same
//! bits, without the call.
template <int kWheels = 0>
Eigen::Vector3d wheels_in_body(const Eigen::MatrixXd& G, const double* v, Eigen::Index n_runtime) {
  const Eigen::Index n = kWheels > 0 ? kWheels : n_runtime;
  Eigen::Vector3d out;
  for (int a = 0; a < 3; ++a) {
    double sum = 0.0;
    for (Eigen::Index j = 0; j < n; ++j) sum += G(a, j) * v[j];
    out[a] = sum;
  }
  return out;
}

//! The state's derivative at one point of a step (the wheels' ḣ is the held τ_w itself).
struct Derivative {
  Eigen::Vector4d q_dot;  //!< (w, x, y, z)
  Eigen::Vector3d omega_dot;
};

}  // namespace

template <int kWheels>
void Spacecraft::integrate(BodyState& s, const Eigen::VectorXd& tau_wheels, double t0_s, double dt_s,
                           long long steps) const {
  // The wheel vectors of a size known at compile time (`kWheels` > 0: unrolled, on the stack) and the
  // momenta advanced locally, written back once: each element takes the same operations either way.
  using WheelVector = Eigen::Matrix<double, (kWheels > 0 ? kWheels : Eigen::Dynamic), 1>;
  const WheelVector tau_w = tau_wheels;
  const Eigen::Index n = tau_w.size();
  const Eigen::Vector3d tau_wheels_B_Nm = wheels_in_body<kWheels>(axes_B_, tau_w.data(), n);  // held
  const auto derivative = [&](const Eigen::Vector4d& q_wxyz, const Eigen::Vector3d& omega,
                              const WheelVector& h, const TimeTerms& at) {
    const Quaternion q = quat_from(q_wxyz).normalized();
    Derivative d;
    const Quaternion q_dot = quat_from(q_wxyz) * Quaternion(0.0, omega.x(), omega.y(), omega.z());
    d.q_dot = 0.5 * wxyz_of(q_dot);
    const Eigen::Vector3d h_B = wheels_in_body<kWheels>(axes_B_, h.data(), n);
    const Eigen::Vector3d tau_ext = disturbance_B_Nm(q, at);
    d.omega_dot = inertia_inv_ * (tau_ext - tau_wheels_B_Nm - omega.cross(inertia_ * omega + h_B));
    return d;
  };
  const double h2 = 0.5 * dt_s;
  const double w = dt_s / 6.0;
  // ḣ is τ_w at every point of a step: its RK4 sum is the same every step.
  const WheelVector h_rate_sum = tau_w + 2.0 * tau_w + 2.0 * tau_w + tau_w;
  WheelVector h0 = s.h_wheels_Nms;
  TimeTerms end;
  double end_s = kNaN;  // the previous step's end: its terms are this step's start when the times agree
  for (long long i = 0; i < steps; ++i) {
    const double t_s = t0_s + static_cast<double>(i) * dt_s;
    const TimeTerms start = t_s == end_s ? end : at_time(t_s);
    const TimeTerms middle = at_time(t_s + h2);
    end_s = t_s + dt_s;
    end = at_time(end_s);
    const Eigen::Vector4d q0 = wxyz_of(s.q_NB);
    const WheelVector h_mid = h0 + h2 * tau_w;  // h + h2·ḣ of k1 and of k2
    const Derivative k1 = derivative(q0, s.omega_BN_B_rad_s, h0, start);
    const Derivative k2 =
        derivative(q0 + h2 * k1.q_dot, s.omega_BN_B_rad_s + h2 * k1.omega_dot, h_mid, middle);
    const Derivative k3 =
        derivative(q0 + h2 * k2.q_dot, s.omega_BN_B_rad_s + h2 * k2.omega_dot, h_mid, middle);
    const WheelVector h_end = h0 + dt_s * tau_w;
    const Derivative k4 =
        derivative(q0 + dt_s * k3.q_dot, s.omega_BN_B_rad_s + dt_s * k3.omega_dot, h_end, end);
    s.q_NB = canonical(quat_from(q0 + w * (k1.q_dot + 2.0 * k2.q_dot + 2.0 * k3.q_dot + k4.q_dot)));
    s.omega_BN_B_rad_s += w * (k1.omega_dot + 2.0 * k2.omega_dot + 2.0 * k3.omega_dot + k4.omega_dot);
    h0 += w * h_rate_sum;
  }
  s.h_wheels_Nms = h0;
}

void Spacecraft::advance(BodyState& s, const Eigen::VectorXd& tau_w, double t0_s, double dt_s,
                         long long steps) const {
  // The wheel counts a spec validates (closed_loop_spec.cpp) at compile time; any other at run time.
  const Eigen::Index n = s.h_wheels_Nms.size() == tau_w.size() ? tau_w.size() : 0;
  if (n == 3)
    integrate<3>(s, tau_w, t0_s, dt_s, steps);
  else if (n == 4)
    integrate<4>(s, tau_w, t0_s, dt_s, steps);
  else
    integrate<0>(s, tau_w, t0_s, dt_s, steps);
}

}  // namespace tetra::sim
