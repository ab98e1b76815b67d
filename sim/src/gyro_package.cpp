#include "tetra/sim/gyro_package.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tetra/core/units.hpp"

namespace tetra::sim {

GyroPackage::GyroPackage(const Scenario& scenario, std::vector<FaultSpec> faults, std::uint64_t seed)
    : faults_(std::move(faults)),
      seed_(seed),
      rate_hz_(scenario.rate_hz),
      drop_probability_(scenario.drop_probability),
      reference_options_(scenario.reference),
      unit_(scenario.unit),
      model_(scenario.model),
      thermal_(scenario.thermal) {
  reset();
}

void GyroPackage::reset() {
  const int n = unit_.gyro_count();
  const double dt_s = 1.0 / rate_hz_;
  channels_.clear();
  channels_.reserve(static_cast<std::size_t>(n));
  drop_rngs_.clear();
  for (int i = 0; i < n; ++i) {
    channels_.emplace_back(unit_.gyros[static_cast<std::size_t>(i)], model_, dt_s, seed_, i);
    drop_rngs_.emplace_back(stream_seed(seed_, Stream::kDropped, i));
  }
  reference_rng_ = Rng(stream_seed(seed_, Stream::kReference, -1));
  reference_drop_rng_ = Rng(stream_seed(seed_, Stream::kReferenceDrop, -1));
  last_output_V_.assign(static_cast<std::size_t>(n), 0.0);
  has_last_output_.assign(static_cast<std::size_t>(n), 0);
  stuck_value_V_.assign(faults_.size(), std::nullopt);
  spike_done_.assign(faults_.size(), 0);
  last_reference_period_ = -1;
  truth_history_.clear();
}

double GyroPackage::apply_faults(int i, double v, double t_s, bool& present) {
  const auto iu = static_cast<std::size_t>(i);
  const GyroChannel& ch = channels_[iu];
  for (std::size_t f = 0; f < faults_.size(); ++f) {
    const FaultSpec& fault = faults_[f];
    if (fault.gyro != i + 1 || !fault_active(fault, t_s)) continue;
    const double s = ch.scale_V_per_dps();
    switch (fault.kind) {
      case FaultKind::kBias:
        v += s * fault.size;
        break;
      case FaultKind::kRamp:
        v += s * fault.size * (t_s - fault.at_s);
        break;
      case FaultKind::kScale:
        v += fault.size * (v - ch.bias_V());
        break;
      case FaultKind::kNoise:
        v += (fault.size - 1.0) * s * ch.last_white_noise_dps();
        break;
      case FaultKind::kSpike:
        if (!spike_done_[f]) {
          v += s * fault.size;
          spike_done_[f] = 1;
        }
        break;
      case FaultKind::kStuck:
        if (!stuck_value_V_[f]) stuck_value_V_[f] = has_last_output_[iu] ? last_output_V_[iu] : v;
        v = *stuck_value_V_[f];
        break;
      case FaultKind::kZero:
        v = 0.0;
        break;
      case FaultKind::kDropout:
        present = false;
        break;
      case FaultKind::kInvalid:
        v = std::numeric_limits<double>::quiet_NaN();
        break;
    }
  }
  return v;
}

void GyroPackage::sample(const Eigen::Vector3d& sensed_dps, double t_s, std::vector<double>& raw_V,
                         std::vector<std::uint8_t>& present) {
  const int n = gyro_count();
  raw_V.resize(static_cast<std::size_t>(n));
  present.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    GyroChannel& channel = channels_[iu];
    // The warm-up's bias enters with the true rate, before noise, quantization and saturation.
    double v = thermal_.active()
                   ? channel.sample_axis_V(channel.axis_B().dot(sensed_dps) + thermal_.bias_dps(iu, t_s), t_s)
                   : channel.sample_V(sensed_dps, t_s);
    bool delivered = true;
    // Dropped samples (an option of the scenario, not a fault): drawn every epoch so that the
    // stream does not depend on anything else.
    const double drop_draw = drop_rngs_[iu].uniform();
    if (drop_probability_ > 0.0 && drop_draw < drop_probability_) delivered = false;
    v = apply_faults(i, v, t_s, delivered);
    present[iu] = delivered ? 1 : 0;
    raw_V[iu] = delivered ? v : std::numeric_limits<double>::quiet_NaN();
    if (delivered && std::isfinite(v)) {
      last_output_V_[iu] = v;
      has_last_output_[iu] = 1;
    }
  }
}

namespace {
//! [rad] the reference's deterministic error at time t: the slow bias and the mis-identification episode.
Eigen::Vector3d reference_error_rad(const ReferenceOptions& r, double t_s) {
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  if (r.bias_arcsec != 0.0 && t_s >= r.bias_at_s) {
    const double grown = r.bias_ramp_s > 0.0 ? std::min(1.0, (t_s - r.bias_at_s) / r.bias_ramp_s) : 1.0;
    e += Eigen::Vector3d::Constant(r.bias_arcsec * kArcsecToRad * grown / std::sqrt(3.0));
  }
  if (r.misid_duration_s > 0.0 && t_s >= r.misid_at_s && t_s < r.misid_at_s + r.misid_duration_s)
    e += Eigen::Vector3d(0.6, 0.8, 0.0) * (r.misid_deg * kDegToRad);
  return e;
}
}  // namespace

std::optional<Quaternion> GyroPackage::reference(std::size_t k, const Quaternion& truth_q_RB) {
  if (reference_options_.rate_hz <= 0.0) return std::nullopt;
  const double t_s = static_cast<double>(k) / rate_hz_;
  Quaternion seen = truth_q_RB;
  bool before_first = false;  // a late reference has nothing to show before its latency has passed
  if (reference_options_.latency_s > 0.0) {
    // The truth latency_s ago, interpolated between the epochs around it (the first epoch before that).
    const double t_seen = t_s - reference_options_.latency_s;
    truth_history_.emplace_back(t_s, truth_q_RB);
    while (truth_history_.size() > 2 && truth_history_[1].first <= t_seen) truth_history_.pop_front();
    const auto& [t0, q0] = truth_history_.front();
    before_first = t_seen < t0;
    seen = q0;
    if (truth_history_.size() > 1 && t_seen > t0) {
      const auto& [t1, q1] = truth_history_[1];
      seen = q0.slerp(std::min(1.0, (t_seen - t0) / (t1 - t0)), q1);
    }
  }
  // Reference period of the nominal epoch time (exact integer arithmetic where the rates allow).
  const auto period = static_cast<std::int64_t>(
      std::floor(static_cast<double>(k) * reference_options_.rate_hz / rate_hz_ + 1e-9));
  if (period == last_reference_period_) return std::nullopt;
  last_reference_period_ = period;
  const double sigma_rad = reference_options_.noise_arcsec * kArcsecToRad;
  Eigen::Vector3d error_rad;
  for (int a = 0; a < 3; ++a) error_rad[a] = sigma_rad * reference_rng_.normal();
  const double p_drop = reference_options_.drop_probability;
  if (p_drop > 0.0 && reference_drop_rng_.uniform() < p_drop) return std::nullopt;  // drawn, not delivered
  if (before_first) return std::nullopt;  // (its noise drawn all the same: the stream stays aligned)
  return canonical(seen * quat_exp(error_rad + reference_error_rad(reference_options_, t_s)));
}

}  // namespace tetra::sim
