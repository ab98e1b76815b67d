#include "tetra/sim/gyro_model.hpp"

#include <algorithm>
#include <cmath>

namespace tetra::sim {

GyroChannel::GyroChannel(const GyroCalibration& gyro, const GyroModelOptions& options, double dt_s,
                         std::uint64_t seed, int gyro_index0)
    : axis_B_(gyro.axis_B),
      scale_V_per_dps_(gyro.scale_factor_V_per_dps),
      bias_V_(gyro.bias_V),
      dt_s_(dt_s),
      white_rng_(stream_seed(seed, Stream::kWhiteNoise, gyro_index0)),
      gm_rng_(stream_seed(seed, Stream::kBiasInstability, gyro_index0)),
      rrw_rng_(stream_seed(seed, Stream::kRateRandomWalk, gyro_index0)) {
  if (gyro.noise) {
    const GyroNoise& n = *gyro.noise;
    if (n.arw_dps_rtHz) white_sigma_dps_ = *n.arw_dps_rtHz / std::sqrt(dt_s);
    if (n.bias_instability_dps && *n.bias_instability_dps > 0.0) {
      gm_sigma_dps_ = kGaussMarkovSigmaPerB * *n.bias_instability_dps;
      gm_phi_ = std::exp(-dt_s / options.bias_instability_correlation_s);
      gm_drive_dps_ = gm_sigma_dps_ * std::sqrt(1.0 - gm_phi_ * gm_phi_);
    }
    if (n.rate_random_walk_dps_per_rts) rrw_step_dps_ = *n.rate_random_walk_dps_per_rts * std::sqrt(dt_s);
    if (n.rate_ramp_dps_per_s) ramp_dps_s_ = *n.rate_ramp_dps_per_s;
    if (n.quantization_deg && *n.quantization_deg > 0.0) {
      quant_step_Vs_ = std::abs(scale_V_per_dps_) * std::sqrt(12.0) * *n.quantization_deg;
    }
  }
  if (options.range_dps) {
    const double a = scale_and_bias_V(-*options.range_dps);
    const double b = scale_and_bias_V(*options.range_dps);
    sat_low_V_ = std::min(a, b);
    sat_high_V_ = std::max(a, b);
    saturate_ = true;
  }
}

double GyroChannel::white_noise_dps() {
  if (white_sigma_dps_ == 0.0) return 0.0;
  last_white_dps_ = white_sigma_dps_ * white_rng_.normal();
  return last_white_dps_;
}

double GyroChannel::bias_instability_dps() {
  if (gm_sigma_dps_ == 0.0) return 0.0;
  if (!gm_started_) {
    gm_state_dps_ = gm_sigma_dps_ * gm_rng_.normal();  // stationary start
    gm_started_ = true;
  } else {
    gm_state_dps_ = gm_phi_ * gm_state_dps_ + gm_drive_dps_ * gm_rng_.normal();
  }
  return gm_state_dps_;
}

double GyroChannel::rate_random_walk_dps(double t_s) {
  if (rrw_step_dps_ != 0.0) rrw_state_dps_ += rrw_step_dps_ * rrw_rng_.normal();
  return rrw_state_dps_ + ramp_dps_s_ * t_s;
}

double GyroChannel::quantize_V(double v) {
  if (quant_step_Vs_ == 0.0) return v;
  quant_integral_Vs_ += v * dt_s_;
  const double count = std::floor(quant_integral_Vs_ / quant_step_Vs_ + 0.5);
  const double out = (count - quant_last_count_) * quant_step_Vs_ / dt_s_;
  quant_last_count_ = count;
  return out;
}

double GyroChannel::saturate_V(double v) const {
  if (!saturate_) return v;
  return std::clamp(v, sat_low_V_, sat_high_V_);
}

double GyroChannel::quantization_step_V() const {
  return quant_step_Vs_ / dt_s_;
}

double GyroChannel::sample_axis_V(double rate_dps, double t_s) {
  const double noise_dps = white_noise_dps() + bias_instability_dps() + rate_random_walk_dps(t_s);
  const double v = scale_and_bias_V(rate_dps) + scale_V_per_dps_ * noise_dps;
  return saturate_V(quantize_V(v));
}

double GyroChannel::sample_V(const Eigen::Vector3d& omega_B_dps, double t_s) {
  return sample_axis_V(axis_B_.dot(omega_B_dps), t_s);
}

}  // namespace tetra::sim
