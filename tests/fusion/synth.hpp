#pragma once
// Small synthetic epochs for the pipeline's unit tests and benchmarks (the full simulator lives in sim/):
// a body rate of a constant part plus a slow sinusoidal attitude-control motion, the measurement model of
// docs/interfaces.md §1 with seeded white noise, and injected faults.

#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::test {

struct SynthFault {
  int gyro = 0;  //!< 1..N, 0 = none
  fdi::FaultKind kind = fdi::FaultKind::kNone;
  bool zero = false;  //!< with kStuck: output 0 V instead of holding
  double at_s = 0.0;
  double size = 0.0;  //!< bias, spike [deg/s]; ramp [deg/s²]; scale [relative]; noise [σ multiplier]
  double spike_period_s = 20.0;
};

struct SynthOptions {
  double period_s = 0.1;
  double arw_dps_rtHz = 3.0e-5;                                  //!< white rate noise N
  Eigen::Vector3d rate0_dps = Eigen::Vector3d(0.0, -0.06, 0.0);  //!< constant body rate
  double acs_amplitude_dps = 2.0e-3;                             //!< sinusoidal motion amplitude
  double acs_period_s = 100.0;                                   //!< its period (peak acceleration 2π·A/P)
  double slew_start_s = -1.0;                                    //!< ≥ 0: a slew starts here
  double slew_rate_dps = 1.0;                                    //!< its peak rate, reached in slew_ramp_s
  double slew_ramp_s = 5.0;
  double slew_hold_s = 30.0;
  Eigen::Vector3d slew_axis = Eigen::Vector3d(0.0, 0.6, 0.8);  //!< unit axis in B
  double reference_period_s = 0.0;                             //!< > 0: reference every this many seconds
  double reference_sigma_arcsec = 5.0;
  std::uint64_t seed = 1;
};

class Synth {
 public:
  Synth(Calibration cal, SynthOptions opt, SynthFault fault = {})
      : cal_(std::move(cal)), opt_(opt), fault_(fault), rng_(opt.seed), n_(cal_.gyro_count()) {
    epoch_.raw.resize(static_cast<std::size_t>(n_));
    epoch_.present.resize(static_cast<std::size_t>(n_));
    held_.assign(static_cast<std::size_t>(n_), 0.0);
  }

  //! True body rate [deg/s] at time t.
  Eigen::Vector3d rate_dps(double t) const {
    const double w = 2.0 * kPi / opt_.acs_period_s;
    const double a = opt_.acs_amplitude_dps;
    Eigen::Vector3d r = opt_.rate0_dps + Eigen::Vector3d(a * std::sin(w * t), a * std::sin(w * t + 1.0),
                                                         a * std::cos(w * t + 2.0));
    if (opt_.slew_start_s >= 0.0) {
      const double u = t - opt_.slew_start_s;
      const double up = opt_.slew_ramp_s;
      const double hold = opt_.slew_hold_s;
      double f = 0.0;
      if (u > 0.0 && u < up) f = u / up;
      if (u >= up && u < up + hold) f = 1.0;
      if (u >= up + hold && u < 2.0 * up + hold) f = 1.0 - (u - up - hold) / up;
      r += f * opt_.slew_rate_dps * opt_.slew_axis;
    }
    return r;
  }

  const fdi::Epoch& next() {
    const double t = static_cast<double>(k_) * opt_.period_s;
    epoch_.stamp_ns = seconds_to_ns(t);
    const Eigen::Vector3d w = rate_dps(t);
    const double sigma = opt_.arw_dps_rtHz / std::sqrt(opt_.period_s);
    for (int i = 0; i < n_; ++i) {
      const auto& g = cal_.gyros[static_cast<std::size_t>(i)];
      double y = g.axis_B.dot(w) + sigma * normal_(rng_);
      bool present = true;
      const bool faulty = fault_.gyro == i + 1 && t >= fault_.at_s;
      double raw = 0.0;
      if (faulty) {
        const double dt = t - fault_.at_s;
        switch (fault_.kind) {
          case fdi::FaultKind::kBias:
            y += fault_.size;
            break;
          case fdi::FaultKind::kRamp:
            y += fault_.size * dt;
            break;
          case fdi::FaultKind::kScale:
            y += fault_.size * g.axis_B.dot(w);
            break;
          case fdi::FaultKind::kNoise:
            y += (fault_.size - 1.0) * sigma * normal_(rng_);
            break;
          case fdi::FaultKind::kSpike:
            if (std::fmod(dt, fault_.spike_period_s) < 0.5 * opt_.period_s) y += fault_.size;
            break;
          default:
            break;
        }
      }
      raw = g.scale_factor_V_per_dps * y + g.bias_V;
      if (faulty && fault_.kind == fdi::FaultKind::kStuck)
        raw = fault_.zero ? 0.0 : held_[static_cast<std::size_t>(i)];
      if (faulty && fault_.kind == fdi::FaultKind::kDropout) present = false;
      if (faulty && fault_.kind == fdi::FaultKind::kInvalid) raw = std::numeric_limits<double>::quiet_NaN();
      if (!faulty) held_[static_cast<std::size_t>(i)] = raw;
      epoch_.raw[static_cast<std::size_t>(i)] = raw;
      epoch_.present[static_cast<std::size_t>(i)] = present ? 1 : 0;
    }
    // Samples are the instantaneous rate at the sample time (as in sim/); the truth attitude is propagated in
    // ten sub-steps per sample so that it is exact well below the tests' tolerances.
    if (k_ > 0) {
      for (int j = 1; j <= 10; ++j) {
        q_ = propagate(q_, rate_dps(t - opt_.period_s + (j - 0.5) * opt_.period_s / 10.0) * kDegToRad,
                       opt_.period_s / 10.0);
      }
    }
    epoch_.reference_q_RB.reset();
    if (opt_.reference_period_s > 0.0) {
      const auto every = static_cast<std::int64_t>(std::llround(opt_.reference_period_s / opt_.period_s));
      if (k_ % every == 0) {
        const double s = opt_.reference_sigma_arcsec * kArcsecToRad;
        const Eigen::Vector3d e(s * normal_(rng_), s * normal_(rng_), s * normal_(rng_));
        epoch_.reference_q_RB = q_ * quat_exp(e);
      }
    }
    ++k_;
    return epoch_;
  }

  const Quaternion& truth_q() const { return q_; }
  double time_s() const { return static_cast<double>(k_ - 1) * opt_.period_s; }

 private:
  Calibration cal_;
  SynthOptions opt_;
  SynthFault fault_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  int n_;
  std::int64_t k_ = 0;
  fdi::Epoch epoch_;
  std::vector<double> held_;
  Quaternion q_ = Quaternion::Identity();
};

}  // namespace tetra::test
