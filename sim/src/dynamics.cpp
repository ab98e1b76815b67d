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

Eigen::Vector3d Spacecraft::disturbance_B_Nm(const Quaternion& q_NB, double t_s) const {
  const double n = orbit_rate_rad_s_;
  Eigen::Vector3d tau = disturbance_.constant_Nm + disturbance_.periodic_Nm * std::sin(n * t_s);
  if (disturbance_.gravity_gradient) {
    // Zenith = −Z of the orbit frame; in B through N.
    const Eigen::Vector3d zenith_N = orbit_frame_q_NO(n, t_s) * Eigen::Vector3d(0.0, 0.0, -1.0);
    const Eigen::Vector3d r_B = q_NB.conjugate() * zenith_N;
    tau += 3.0 * n * n * r_B.cross(inertia_ * r_B);
  }
  return tau;
}

Spacecraft::Derivative Spacecraft::derivative(const Eigen::Vector4d& q_wxyz, const Eigen::Vector3d& omega,
                                              const Eigen::VectorXd& h, const Eigen::VectorXd& tau_w,
                                              double t_s) const {
  const Quaternion q = quat_from(q_wxyz).normalized();
  Derivative d;
  const Quaternion q_dot = quat_from(q_wxyz) * Quaternion(0.0, omega.x(), omega.y(), omega.z());
  d.q_dot = 0.5 * wxyz_of(q_dot);
  const Eigen::Vector3d h_B = axes_B_ * h;
  const Eigen::Vector3d tau_ext = disturbance_B_Nm(q, t_s);
  d.omega_dot = inertia_inv_ * (tau_ext - axes_B_ * tau_w - omega.cross(inertia_ * omega + h_B));
  d.h_dot = tau_w;
  return d;
}

void Spacecraft::step(BodyState& s, const Eigen::VectorXd& tau_w, double t_s, double dt_s) const {
  const Eigen::Vector4d q0 = wxyz_of(s.q_NB);
  const Derivative k1 = derivative(q0, s.omega_BN_B_rad_s, s.h_wheels_Nms, tau_w, t_s);
  const double h2 = 0.5 * dt_s;
  const Derivative k2 = derivative(q0 + h2 * k1.q_dot, s.omega_BN_B_rad_s + h2 * k1.omega_dot,
                                   s.h_wheels_Nms + h2 * k1.h_dot, tau_w, t_s + h2);
  const Derivative k3 = derivative(q0 + h2 * k2.q_dot, s.omega_BN_B_rad_s + h2 * k2.omega_dot,
                                   s.h_wheels_Nms + h2 * k2.h_dot, tau_w, t_s + h2);
  const Derivative k4 = derivative(q0 + dt_s * k3.q_dot, s.omega_BN_B_rad_s + dt_s * k3.omega_dot,
                                   s.h_wheels_Nms + dt_s * k3.h_dot, tau_w, t_s + dt_s);
  const double w = dt_s / 6.0;
  s.q_NB = canonical(quat_from(q0 + w * (k1.q_dot + 2.0 * k2.q_dot + 2.0 * k3.q_dot + k4.q_dot)));
  s.omega_BN_B_rad_s += w * (k1.omega_dot + 2.0 * k2.omega_dot + 2.0 * k3.omega_dot + k4.omega_dot);
  s.h_wheels_Nms += w * (k1.h_dot + 2.0 * k2.h_dot + 2.0 * k3.h_dot + k4.h_dot);
}

}  // namespace tetra::sim
