#include "reference_monitor.hpp"

#include <algorithm>
#include <cmath>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

ReferenceMonitor::ReferenceMonitor(const Eigen::MatrixX3d& axes_B, const PipelineConfig& config)
    : axes_B_(axes_B),
      config_(config),
      n_(static_cast<std::size_t>(axes_B.rows())),
      tracks_(n_),
      snap_ns_(kSnapshots, 0),
      snap_q_(kSnapshots, Quaternion::Identity()),
      snap_angle_(static_cast<std::size_t>(kSnapshots) * n_, 0.0),
      snap_ref_(static_cast<std::size_t>(kSnapshots) * n_, 0.0),
      snap_theta_(kSnapshots, Eigen::Vector3d::Zero()),
      sigma_ref_rad_(config.reference_sigma_arcsec * kArcsecToRad) {}

void ReferenceMonitor::reset() {
  sigma_ref_rad_ = config_.reference_sigma_arcsec * kArcsecToRad;
  for (auto& t : tracks_) t = Track{};
  snap_count_ = 0;
  windows_.reset();
  filter_.reset();
}

std::optional<ReferenceFinding> ReferenceMonitor::filter_update(const Mekf& filter, GyroMask active) {
  filter_.begin();
  for (int id = 1; id <= filter.gyro_count(); ++id) {
    if (has_gyro(active, id)) filter_.add(id, std::abs(filter.bias_z(id)), config_.reference_threshold_sigma);
  }
  const int culprit = filter_.confirm(design::reference_confirm_count, 3);
  if (culprit == 0) return std::nullopt;
  ReferenceFinding found{culprit, filter_.statistic(), false, {}};
  filter_.rows(EvidenceSource::kFilterBias, active, found.rows, false);
  return found;
}

void LoneGyro::begin() {
  flagged_ = loud_ = culprit_ = members_ = 0;
  stat_ = 0.0;
}

void LoneGyro::add(int id, double z, double threshold) {
  if (members_ < kMaxGyros) {
    member_id_[static_cast<std::size_t>(members_)] = id;
    member_z_[static_cast<std::size_t>(members_)] = z;
  }
  threshold_ = threshold;
  ++members_;
  if (z > threshold) {
    ++flagged_;
    culprit_ = id;
    stat_ = z;
  } else if (z > design::lone_gyro_others_fraction * threshold) {
    ++loud_;
  }
}

void LoneGyro::rows(EvidenceSource source, GyroMask active, EvidenceRows& out, bool judge_others) const {
  const int members = std::min(members_, kMaxGyros);
  const auto largest_without = [&](int j) {
    double z = 0.0;
    for (int m = 0; m < members; ++m) {
      if (member_id_[static_cast<std::size_t>(m)] != j)
        z = std::max(z, member_z_[static_cast<std::size_t>(m)]);
    }
    return z;
  };
  for (int j = 1; j <= kMaxGyros; ++j) {
    if (!has_gyro(active, j)) continue;
    const auto h = static_cast<std::uint8_t>(j);
    const LedgerRow row =
        judge(source, h, largest_without(j), design::lone_gyro_others_fraction * threshold_, threshold_);
    out.add(judge_others || row.verdict != RowVerdict::kRejected
                ? row
                : stated(source, h, RowVerdict::kNoCall, row.statistic, threshold_));
  }
  out.add(judge(source, kHypothesisNone, largest_without(0), design::lone_gyro_others_fraction * threshold_,
                threshold_));
  const bool lone = flagged_ == 1 && loud_ == 0;
  out.add(stated(source, kHypothesisReference, lone ? RowVerdict::kRejected : RowVerdict::kNoCall, stat_,
                 threshold_));
}

int LoneGyro::confirm(int count, int min_members) {
  if (flagged_ != 1 || loud_ != 0 || members_ < min_members) {
    reset();
    return 0;
  }
  if (culprit_ != run_gyro_) {
    run_gyro_ = culprit_;
    run_ = 0;
  }
  if (++run_ < count) return 0;
  reset();
  return culprit_;
}

void ReferenceMonitor::integrate(const EpochFrame& frame, GyroMask excluded,
                                 const Eigen::Vector3d& omega_meas_B_rad_s,
                                 const Eigen::Vector3d& earth_B_rad_s, bool estimate_fresh) {
  // Samples are instantaneous rates at the sample time: the increment over (t_{k−1}, t_k] is the trapezoid.
  for (std::size_t u = 0; u < n_; ++u) {
    const int id = static_cast<int>(u) + 1;
    if (has_gyro(excluded, id)) continue;
    auto& t = tracks_[u];
    const auto row = static_cast<Eigen::Index>(u);
    const bool own = has_gyro(frame.usable, id);
    const double yi = own ? frame.y_rad_s[u] : axes_B_.row(row).dot(omega_meas_B_rad_s);
    if (!own && !estimate_fresh) t.held_ns = frame.now_ns;
    if (frame.dt_s > 0.0)
      t.angle_rad += (0.5 * (t.prev_int_y + yi) - axes_B_.row(row).dot(earth_B_rad_s)) * frame.dt_s;
    t.prev_int_y = yi;
  }
}

void ReferenceMonitor::snapshot(std::int64_t now_ns, const Quaternion& q) {
  // The reference's rotation about each gyro axis, summed over its own increments: one increment spans one
  // reference period, so the non-commutativity of a long window (slews) does not enter.
  Eigen::Vector3d theta = Eigen::Vector3d::Zero();
  if (snap_count_ > 0) {
    const Eigen::Vector3d inc_B = quat_log(snap_q_[slot(snap_count_ - 1)].conjugate() * q);
    for (std::size_t i = 0; i < n_; ++i)
      tracks_[i].ref_angle_rad += axes_B_.row(static_cast<Eigen::Index>(i)).dot(inc_B);
    theta = snap_theta_[slot(snap_count_ - 1)] + inc_B;
  }
  const std::size_t s = slot(snap_count_);
  snap_theta_[s] = theta;
  snap_ns_[s] = now_ns;
  snap_q_[s] = q;
  for (std::size_t i = 0; i < n_; ++i) {
    snap_angle_[s * n_ + i] = tracks_[i].angle_rad;
    snap_ref_[s * n_ + i] = tracks_[i].ref_angle_rad;
  }
  ++snap_count_;
}

int ReferenceMonitor::first_snapshot_from(std::int64_t from_ns, int end) const {
  // Snapshot times rise strictly with k (accepted epochs only): a binary search over the kept ones.
  int lo = std::max(0, snap_count_ - kSnapshots);
  int hi = end;
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (snap_ns_[slot(mid)] < from_ns) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

int ReferenceMonitor::window_start(std::int64_t now_ns) const {
  const std::int64_t window = seconds_to_ns(config_.reference_window_s);
  const int k = first_snapshot_from(now_ns - window, snap_count_ - 1);  // now − t_k ≤ window
  if (k >= snap_count_ - 1) return -1;
  return now_ns - snap_ns_[slot(k)] < window / 2 ? -1 : k;
}

std::optional<ReferenceFinding> ReferenceMonitor::update(std::int64_t now_ns, const Quaternion& q_RB,
                                                         GyroMask excluded, const GyroSeries& series) {
  snapshot(now_ns, canonical(q_RB));
  const int old = window_start(now_ns);
  if (old < 0) return std::nullopt;
  const double span = ns_to_seconds(now_ns - snap_ns_[slot(old)]);
  windows_.begin();
  for (std::size_t i = 0; i < n_; ++i) {
    const int id = static_cast<int>(i) + 1;
    if (has_gyro(excluded, id)) continue;
    const auto& t = tracks_[i];
    if (t.held_ns >= snap_ns_[slot(old)]) continue;  // its angle holds a stale rate over this window
    const double rot = t.ref_angle_rad - snap_ref(old, static_cast<int>(i));
    const double err =
        beyond_calibration(series.constants(id), (t.angle_rad - snap_angle(old, static_cast<int>(i))) - rot,
                           rot, old, snap_count_ - 1);
    windows_.add(id, std::abs(err) / disagreement_sigma(series.constants(id), span, rot),
                 config_.reference_threshold_sigma);
  }
  // One gyro alone beyond the threshold, the others quiet, in `reference_confirm_count` consecutive
  // comparisons (consecutive windows share no reference sample, so one wild reference sample cannot do it).
  const int culprit = windows_.confirm(design::reference_confirm_count, 2);
  if (culprit == 0) return std::nullopt;
  ReferenceFinding found{culprit, windows_.statistic(), scale_significant(culprit, old), {}};
  windows_.rows(EvidenceSource::kReferenceWindow, all_gyros(static_cast<int>(n_)) & ~excluded, found.rows);
  return found;
}

double ReferenceMonitor::disagreement_sigma(const GyroConstants& c, double span_s, double rot_rad) const {
  // Two reference samples, white noise over the span, the calibrated bias and its instability acting over
  // it, the calibrated scale factor on the rotation, and the angle quantization at both ends.
  const double sig_ref = sigma_ref_rad_;
  return std::sqrt(2.0 * sig_ref * sig_ref + c.arw_rad_rts * c.arw_rad_rts * span_s +
                   std::pow((c.bias_sigma_rad_s + c.bias_instability_rad_s) * span_s, 2) +
                   std::pow(c.scale_rel_sigma * rot_rad, 2) + 2.0 * c.quantization_rad * c.quantization_rad);
}

double ReferenceMonitor::beyond_calibration(const GyroConstants& c, double err, double rot, int old,
                                            int last) const {
  // As the parity's dead zone (docs/fdi.md, "Calibration uncertainty"): a scale factor off by ε and an axis
  // off by δh add −ε·rot + δh·Θ to the disagreement; within e stated σ that is at most the bound below.
  const Eigen::Vector3d theta = snap_theta_[slot(last)] - snap_theta_[slot(old)];
  const double bound = config_.calibration_error_sigmas *
                       (c.scale_rel_sigma * std::abs(rot) + c.axis_sigma.dot(theta.cwiseAbs()));
  if (!(bound > 0.0)) return err;
  return std::abs(err) <= bound ? 0.0 : err - std::copysign(bound, err);
}

bool ReferenceMonitor::span(std::int64_t from_ns, double min_span_s, GyroMask excluded,
                            const GyroSeries& series, SpanDisagreement& out) const {
  out.start = -1;
  if (snap_count_ < 2) return false;
  const int last = snap_count_ - 1;
  const int old = first_snapshot_from(from_ns, last);
  if (old >= last) return false;
  out.span_s = ns_to_seconds(snap_ns_[slot(last)] - snap_ns_[slot(old)]);
  if (out.span_s < min_span_s) return false;
  out.start = old;
  out.start_ns = snap_ns_[slot(old)];
  out.gyros = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    const int id = static_cast<int>(i) + 1;
    if (has_gyro(excluded, id) || tracks_[i].held_ns >= out.start_ns) continue;
    const int g = static_cast<int>(i);
    const double rot = snap_ref(last, g) - snap_ref(old, g);
    out.err_rad[i] = beyond_calibration(series.constants(id),
                                        (snap_angle(last, g) - snap_angle(old, g)) - rot, rot, old, last);
    out.sigma_rad[i] = disagreement_sigma(series.constants(id), out.span_s, rot);
    out.gyros |= GyroMask{1} << i;
  }
  return true;
}

bool ReferenceMonitor::scale_significant(int culprit, int old) const {
  // Scale or rate offset: fit err(τ) = a·τ + b·rot(τ) over the window's snapshots. When the rotation about
  // the axis is not proportional to time (a slew), a significant b is a scale error; otherwise the data
  // cannot tell scale from offset.
  const int c = culprit - 1;
  double stt = 0.0, str = 0.0, srr = 0.0, ste = 0.0, sre = 0.0;
  for (int k = old + 1; k < snap_count_; ++k) {
    const double tau = ns_to_seconds(snap_ns_[slot(k)] - snap_ns_[slot(old)]);
    const double rot = snap_ref(k, c) - snap_ref(old, c);
    const double err = (snap_angle(k, c) - snap_angle(old, c)) - rot;
    stt += tau * tau;
    str += tau * rot;
    srr += rot * rot;
    ste += tau * err;
    sre += rot * err;
  }
  const double det = stt * srr - str * str;
  if (!(stt > 0.0 && srr > 0.0 && det > 1e-4 * stt * srr)) return false;  // |corr(τ, rot)| ≥ 0.99995
  const double b = (stt * sre - str * ste) / det;
  const double sig_ref = sigma_ref_rad_;
  const double sigma_b = std::sqrt(2.0) * sig_ref * std::sqrt(stt / det);
  return std::abs(b) > design::scale_slope_sigmas * sigma_b;
}

}  // namespace tetra::fdi::detail
