#include "isolator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tetra/core/units.hpp"

namespace tetra::fdi::detail {

Isolator::Isolator(int n_gyros, const PipelineConfig& config)
    : n_(n_gyros),
      config_(config),
      glt_sum_(Eigen::VectorXd::Zero(std::max(1, n_gyros - 3))),
      glt_pre_(Eigen::VectorXd::Zero(std::max(1, n_gyros - 3))),
      glt_noise_cov_(Eigen::MatrixXd::Identity(std::max(1, n_gyros - 3), std::max(1, n_gyros - 3))),
      glt_y_pre_(static_cast<std::size_t>(n_gyros), 0.0),
      hist_y_(static_cast<std::size_t>(kHistory) * static_cast<std::size_t>(n_gyros), 0.0),
      hist_valid_(kHistory, 0),
      hist_ns_(kHistory, 0),
      mean_pre_(static_cast<std::size_t>(n_gyros), 0.0),
      mean_post_(static_cast<std::size_t>(n_gyros), 0.0),
      n_pre_(static_cast<std::size_t>(n_gyros), 0),
      n_post_(static_cast<std::size_t>(n_gyros), 0),
      drift_x_(kHistory, 0.0),
      drift_t_(kHistory, 0.0) {
  // One scratch vector per parity dimension, so the GLT never resizes (allocates) one.
  for (int d = 0; d <= std::max(1, n_gyros - 3); ++d) {
    glt_mean_.push_back(Eigen::VectorXd::Zero(d));
    glt_w_.push_back(Eigen::VectorXd::Zero(d));
    glt_cov_.push_back(Eigen::MatrixXd::Zero(d, d));
    glt_ldlt_.emplace_back(d);
  }
}

void Isolator::close() {
  episode_.active = false;
  episode_.declared_unisolated = false;
  glt_sum_.setZero();
  glt_n_ = 0;
  glt_omega_sum_.setZero();
  glt_baseline_done_ = false;
  glt_pre_n_ = 0;
  glt_noise_cov_.setIdentity();
}

std::int64_t Isolator::time_of(std::int64_t index) const {
  return hist_ns_[static_cast<std::size_t>(index % kHistory)];
}

void Isolator::record(const EpochFrame& frame) {
  const auto slot = static_cast<std::size_t>(frame.index % kHistory);
  hist_ns_[slot] = frame.now_ns;
  std::copy(frame.y_rad_s.begin(), frame.y_rad_s.end(),
            hist_y_.begin() + static_cast<std::ptrdiff_t>(slot * static_cast<std::size_t>(n_)));
  hist_valid_[slot] = frame.valid;
}

bool Isolator::open(const Detection& detection, std::int64_t now_ns, std::int64_t index, const Subset& s,
                    const ParityDetector& detector, const Eigen::Vector3d& omega_rad_s) {
  if (episode_.active) return false;
  episode_.active = true;
  episode_.declared_unisolated = false;
  episode_.detect_ns = now_ns;
  episode_.deadline_ns = now_ns + seconds_to_ns(design::isolation_window_s);
  episode_.onset_index = detection.onset_index;
  episode_.onset_ns = time_of(std::max<std::int64_t>(detection.onset_index, 0));
  if (index - detection.onset_index >= kHistory) episode_.onset_ns = now_ns;
  episode_.test = detection.test;
  episode_.statistic = detection.statistic;
  glt_baseline_done_ = false;
  glt_pre_n_ = 0;
  if (s.dof >= 2) {  // the GLT starts from the parity the vector CUSUM summed since its change time
    glt_sum_.head(s.dof) = detector.vector_sum().head(s.dof);
    glt_n_ = detector.vector_count();
    glt_omega_sum_ = omega_rad_s * glt_n_;  // the epochs before the opening at this epoch's rate
  }
  return true;
}

void Isolator::accumulate(const Eigen::VectorXd& p, int dof, const Eigen::Vector3d& omega_rad_s) {
  if (!episode_.active || dof < 2) return;
  glt_sum_.head(dof) += p.head(dof);
  glt_omega_sum_ += omega_rad_s;
  ++glt_n_;
}

Verdict Isolator::decide(std::int64_t now_ns, std::int64_t index, GyroMask active, SubsetCache& subsets,
                         const GyroSeries& series, Isolation& found) {
  if (!episode_.active) return Verdict::kNone;
  rows_.clear();
  Evidence evidence = Evidence::kOnset;
  int culprit = onset_test(index, active, subsets, series);
  if (culprit == 0) {
    const Subset& s = subsets.get(active);
    if (s.dof >= 2 && glt_n_ >= 3) rows_.clear();  // the GLT runs: its rows, not the silent onset test's
    if (!glt_baseline_done_) glt_baseline(index, s, subsets.sqrt_period());
    culprit = glt_test(s, subsets);
    evidence = Evidence::kGlt;
  }
  if (culprit > 0) {
    // Kind from the gyro's own samples: identical raw values (stuck_repeat_isolated or more in a row,
    // whatever the onset estimate) are a stuck output; a noise increase also shifts window means, and its
    // second differences tell it apart.
    const bool repeated = series.repeat_count(culprit) >= design::stuck_repeat_isolated;
    const int last = static_cast<int>(std::max<std::int64_t>(index - episode_.onset_index, 20));
    const double r = series.recent_noise_ratio(culprit, subsets.sqrt_period(), last);
    // While the body moves, second differences carry its jerk: a raised level may be motion, not noise.
    const bool quiet = series.motion_quiet(culprit, subsets.sqrt_period(), last);
    const bool raised = std::isfinite(r) && r > design::noise_raised_fraction * config_.noise_high_ratio;
    // A noise level neither normal nor clearly high: wait for more samples rather than guess the kind.
    const bool ambiguous = !repeated && raised && quiet && r <= config_.noise_high_ratio;
    if (ambiguous) return Verdict::kNone;
    FaultKind kind = FaultKind::kBias;
    if (repeated) {
      kind = FaultKind::kStuck;
    } else if (raised && !quiet) {
      kind = FaultKind::kUnknown;
    } else if (raised && r > config_.noise_high_ratio) {
      kind = FaultKind::kNoise;
    } else if (evidence == Evidence::kGlt) {
      kind = classify_drift(culprit, index, active, subsets, rows_);
    }
    found = {culprit, kind, evidence, episode_.test, episode_.statistic, rows_};
    return Verdict::kIsolated;
  }
  if (!episode_.declared_unisolated && now_ns >= episode_.deadline_ns) {
    episode_.declared_unisolated = true;
    return Verdict::kUnisolated;
  }
  if (now_ns - episode_.last_alarm_ns > seconds_to_ns(config_.clear_after_s)) {
    episode_.active = false;
    return Verdict::kCleared;
  }
  return Verdict::kNone;
}

double Isolator::window_means(std::int64_t b, std::int64_t e, std::vector<double>& mean,
                              std::vector<int>& count) const {
  double t_mean = 0.0;
  for (std::int64_t k = b; k < e; ++k) {
    const auto slot = static_cast<std::size_t>(k % kHistory);
    t_mean += ns_to_seconds(hist_ns_[slot] - time_of(b));
    for (int i = 0; i < n_; ++i) {
      if (!has_gyro(hist_valid_[slot], i + 1)) continue;
      mean[static_cast<std::size_t>(i)] += y_at(slot, i);
      ++count[static_cast<std::size_t>(i)];
    }
  }
  t_mean /= static_cast<double>(e - b);
  for (std::size_t i = 0; i < mean.size(); ++i) {
    if (count[i] > 0) mean[i] /= count[i];
  }
  return t_mean;
}

int Isolator::motion_within_bound(GyroMask mask, double separation_s, SubsetCache& subsets,
                                  const GyroSeries& series, double* ratio) const {
  const Subset& h = subsets.get(mask);
  if (ratio != nullptr) *ratio = std::numeric_limits<double>::quiet_NaN();
  if (!h.observable) return -1;
  Eigen::Vector3d dw = Eigen::Vector3d::Zero();
  double var = 0.0;
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(mask, i + 1)) continue;
    const auto u = static_cast<std::size_t>(i);
    if (n_pre_[u] < 2 || n_post_[u] < 2) return -1;
    dw += h.pinv.col(i) * (mean_post_[u] - mean_pre_[u]);
    if (h.quantized) {  // a window mean's quantization error telescopes
      var += h.pinv.col(i).squaredNorm() *
             (series.window_mean_variance(i + 1, subsets.sqrt_period(), n_pre_[u]) +
              series.window_mean_variance(i + 1, subsets.sqrt_period(), n_post_[u]));
    } else {
      const double sig = series.sample_sigma(i + 1, subsets.sqrt_period());
      var += h.pinv.col(i).squaredNorm() * sig * sig * (1.0 / n_pre_[u] + 1.0 / n_post_[u]);
    }
  }
  const double a_max = config_.max_angular_acceleration_dps2 * kDegToRad;
  const double bound = a_max * separation_s + config_.onset_sigma * std::sqrt(var);
  if (ratio != nullptr) *ratio = dw.norm() / bound;
  return dw.norm() <= bound ? 1 : 0;
}

double Isolator::two_windows(std::int64_t b1, std::int64_t e1, std::int64_t b2, std::int64_t e2) {
  std::fill(mean_pre_.begin(), mean_pre_.end(), 0.0);
  std::fill(mean_post_.begin(), mean_post_.end(), 0.0);
  std::fill(n_pre_.begin(), n_pre_.end(), 0);
  std::fill(n_post_.begin(), n_post_.end(), 0);
  const double t1 = window_means(b1, e1, mean_pre_, n_pre_);
  const double t2 = window_means(b2, e2, mean_post_, n_post_);
  return ns_to_seconds(time_of(b2) - time_of(b1)) + t2 - t1;
}

int Isolator::onset_test(std::int64_t index, GyroMask active, SubsetCache& subsets,
                         const GyroSeries& series) {
  const std::int64_t k0 = episode_.onset_index;
  const std::int64_t gap = 2;
  const std::int64_t pre_begin = k0 - gap - design::onset_pre_epochs;
  const std::int64_t pre_end = k0 - gap;
  const std::int64_t post_end = std::min(index + 1, k0 + design::onset_post_max_epochs);
  if (post_end - k0 < design::onset_min_post_epochs) return 0;  // not yet: the test runs on a later epoch
  double ratio = std::numeric_limits<double>::quiet_NaN();
  // The onset's window before it is no longer kept (or precedes the first epoch): it cannot run.
  if (pre_begin < 0 || pre_begin <= index - kHistory) return no_call(active, ratio);
  // Every hypothesis below is judged against the acceleration bound. Before the onset the data are clean:
  // when the body already turned faster than the bound there (a slew the bound does not cover), the true
  // hypothesis may be the impossible one and a wrong one possible by chance. Nothing can be told.
  const std::int64_t pre_mid = pre_begin + design::onset_pre_epochs / 2;
  if (motion_within_bound(active, two_windows(pre_begin, pre_mid, pre_mid, pre_end), subsets, series,
                          &ratio) == 0)
    return no_call(active, ratio);
  // After the onset a step is constant: the data since then, the fault included, must not show the body
  // turning beyond the bound either. Otherwise a motion that began too gently to show before the onset may be
  // what one gyro sees alone (its axis the only one that sees it, another stuck), and it is not a step.
  const std::int64_t post_mid = k0 + (post_end - k0) / 2;
  if (motion_within_bound(active, two_windows(k0, post_mid, post_mid, post_end), subsets, series, &ratio) ==
      0)
    return no_call(active, ratio);
  const double separation = two_windows(pre_begin, pre_end, k0, post_end);
  // All gyros consistent with a possible motion: no abrupt change beyond motion, nothing to tell. Each
  // hypothesis's row: the rate change of the gyros it holds healthy over the motion bound (docs/fdi.md).
  const int all = motion_within_bound(active, separation, subsets, series, &ratio);
  rows_.add(stated(EvidenceSource::kOnset, kHypothesisNone,
                   all == 0 ? RowVerdict::kRejected : RowVerdict::kNoCall, ratio, 1.0));
  if (all != 0) return 0;
  // The onset is in the gyros' own data: a wrong reference does not move them.
  rows_.add(stated(EvidenceSource::kOnset, kHypothesisReference, RowVerdict::kRejected, ratio, 1.0));
  int count = 0;
  int culprit = 0;
  for (int j = 1; j <= n_; ++j) {
    if (!has_gyro(active, j)) continue;
    const int c = motion_within_bound(without_gyro(active, j), separation, subsets, series, &ratio);
    rows_.add(stated(EvidenceSource::kOnset, static_cast<std::uint8_t>(j),
                     c < 0 ? RowVerdict::kNoCall : (c == 1 ? RowVerdict::kConsistent : RowVerdict::kRejected),
                     ratio, 1.0));
    if (c < 0) return 0;
    if (c == 1) {
      ++count;
      culprit = j;
    }
  }
  return count == 1 ? culprit : 0;
}

int Isolator::no_call(GyroMask active, double ratio) {
  rows_.add(stated(EvidenceSource::kOnset, kHypothesisNone, RowVerdict::kNoCall, ratio, 1.0));
  for (int j = 1; j <= n_; ++j) {
    if (has_gyro(active, j))
      rows_.add(
          stated(EvidenceSource::kOnset, static_cast<std::uint8_t>(j), RowVerdict::kNoCall, ratio, 1.0));
  }
  return 0;
}

// GLT on the mean normalized parity since the onset (N ≥ 5). Under hypothesis i the mean is a fault along
// gyro i's column w_i, plus the calibration's term, plus white noise. With C the covariance of what is not
// the fault, the residual after fitting the best fault along w_i, mᵀC⁻¹m − (w_iᵀC⁻¹m)²/(w_iᵀC⁻¹w_i), is
// χ²_{d−1} under hypothesis i. Two forms of m and C:
// - the mean alone, m = p̄: the calibration's term at the mean rate ω̄, C_cal(ω̄) from the stated 1σ times
//   calibration_error_sigmas (biases, scale factors, axes) and the wandering bias's, plus Σ/n;
// - the mean minus the baseline before the onset (`glt_baseline`), m = p̄ − p̄_pre: the term is linear in the
//   rate and its bias part constant, so what is left is that of the rate's change, C_cal(ω̄ − ω̄_pre) without
//   the biases, plus Σ(1/n + 1/n_pre). A fault that began before the baseline's window moves both means along
//   w_i: m stays on gyro i's line.
// Σ is the white noise's covariance the baseline shows (`baseline_noise`, at least the model's I). Each
// hypothesis's statistic is the larger of the two (the first form is capped by the biases' term, the second
// by the baseline's noise): a true hypothesis is rejected above χ²_{d−1}(1 − p_glt) (p_glt: budget.hpp,
// BudgetTest::kGlt) with at most twice that probability for a unit within its calibration's tolerance — and
// only then can a healthy gyro be excluded. Two gyros whose columns the calibration's term can confuse stay
// both consistent: the episode waits for more evidence or ends `unisolated` (docs/fdi.md, "GLT").
int Isolator::glt_test(const Subset& s, const SubsetCache& subsets) {
  if (s.dof < 2 || glt_n_ < 3) return 0;
  const double n = glt_n_;
  const Eigen::Vector3d omega_mean = glt_omega_sum_ / n;
  Eigen::VectorXd& mean = glt_mean_[static_cast<std::size_t>(s.dof)];
  Eigen::MatrixXd& cov = glt_cov_[static_cast<std::size_t>(s.dof)];
  double r[kMaxGyros];
  mean = glt_sum_.head(s.dof) / n;
  subsets.calibration_covariance(s, s.mask, omega_mean, true, cov);
  cov.noalias() += glt_noise_cov_.topLeftCorner(s.dof, s.dof) / n;
  glt_residuals(s, mean, cov, r);
  if (glt_pre_n_ > 0) {
    double r_pre[kMaxGyros];
    mean -= glt_pre_.head(s.dof);
    subsets.calibration_covariance(s, s.mask, omega_mean - glt_omega_pre_, false, cov);
    cov.noalias() += glt_noise_cov_.topLeftCorner(s.dof, s.dof) * (1.0 / n + 1.0 / glt_pre_n_);
    glt_residuals(s, mean, cov, r_pre);
    for (int i = 0; i < n_; ++i) r[i] = std::max(r[i], r_pre[i]);
  }
  int best = 0;
  int accepted = 0;
  int rejected = 0;
  int members = 0;
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(s.mask, i + 1)) continue;
    ++members;
    rows_.add(judge(EvidenceSource::kGlt, static_cast<std::uint8_t>(i + 1), r[i], s.glt_accept, s.glt_reject,
                    s.dof - 1));
    if (r[i] <= s.glt_accept) {
      ++accepted;
      best = i + 1;
    } else if (r[i] > s.glt_reject) {
      ++rejected;
    }
  }
  return (accepted == 1 && rejected == members - 1) ? best : 0;
}

void Isolator::glt_residuals(const Subset& s, const Eigen::VectorXd& m, const Eigen::MatrixXd& cov,
                             double* r) const {
  Eigen::LDLT<Eigen::MatrixXd>& ldlt = glt_ldlt_[static_cast<std::size_t>(s.dof)];
  Eigen::VectorXd& w = glt_w_[static_cast<std::size_t>(s.dof)];
  ldlt.compute(cov);
  w = ldlt.solve(m);
  const double m_m = m.dot(w);
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(s.mask, i + 1)) continue;
    w = ldlt.solve(s.parity.col(i));  // C⁻¹·w_i
    const double w_m = w.dot(m);
    r[i] = m_m - w_m * w_m / w.dot(s.parity.col(i));
  }
}

void Isolator::glt_baseline(std::int64_t index, const Subset& s, double sqrt_period) {
  glt_baseline_done_ = true;
  glt_pre_n_ = 0;
  const std::int64_t end = episode_.onset_index - 2;  // the onset test's gap
  const std::int64_t begin =
      std::max({end - design::glt_baseline_max_epochs, index - kHistory + 1, std::int64_t{0}});
  if (end - begin < design::glt_baseline_min_epochs) return;
  std::fill(glt_y_pre_.begin(), glt_y_pre_.end(), 0.0);
  int count = 0;
  for (std::int64_t k = begin; k < end; ++k) {
    const auto slot = static_cast<std::size_t>(k % kHistory);
    if ((hist_valid_[slot] & s.mask) != s.mask) continue;
    for (int i = 0; i < n_; ++i) glt_y_pre_[static_cast<std::size_t>(i)] += y_at(slot, i);
    ++count;
  }
  if (count < design::glt_baseline_min_epochs) return;
  for (double& v : glt_y_pre_) v /= count;
  double p[kMaxGyros];
  (void)apply_parity(s, s.mask, glt_y_pre_.data(), sqrt_period, p);
  for (int r = 0; r < s.dof; ++r) glt_pre_[r] = p[r];
  glt_omega_pre_ = apply_pinv(s.pinv, s.mask, glt_y_pre_.data());
  glt_pre_n_ = count;
  baseline_noise(begin, end, s, sqrt_period);
}

// The noise the baseline's parity shows: a unit noisier than its `noise:` section (or one gyro of it) makes
// the parity's spread larger than the model's identity, and the GLT's white-noise term follows it. The
// sample covariance of means of design::glt_noise_block_epochs epochs, times that count (a mean's covariance,
// in which the angle quantization telescopes away as it does in the GLT's own means; one sample's spread
// would count it whole), each eigenvalue raised to at least the model's 1, so a direction the data show no
// noisier is taken as stated. Once per episode (the eigenvalue solver allocates).
void Isolator::baseline_noise(std::int64_t begin, std::int64_t end, const Subset& s, double sqrt_period) {
  glt_noise_cov_.setIdentity();
  Eigen::MatrixXd scatter = Eigen::MatrixXd::Zero(s.dof, s.dof);
  Eigen::VectorXd block = Eigen::VectorXd::Zero(s.dof);
  double p[kMaxGyros];
  int in_block = 0;
  int blocks = 0;
  for (std::int64_t k = begin; k < end; ++k) {
    const auto slot = static_cast<std::size_t>(k % kHistory);
    if ((hist_valid_[slot] & s.mask) != s.mask) continue;
    (void)apply_parity(s, s.mask, &hist_y_[slot * static_cast<std::size_t>(n_)], sqrt_period, p);
    for (int r = 0; r < s.dof; ++r) block[r] += p[r] - glt_pre_[r];
    if (++in_block < design::glt_noise_block_epochs) continue;
    block /= design::glt_noise_block_epochs;
    scatter.noalias() += block * block.transpose();
    block.setZero();
    in_block = 0;
    ++blocks;
  }
  if (blocks < 2 || !scatter.allFinite()) return;
  scatter *= static_cast<double>(design::glt_noise_block_epochs) / blocks;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scatter);
  const Eigen::VectorXd raised = eig.eigenvalues().cwiseMax(1.0);
  glt_noise_cov_.topLeftCorner(s.dof, s.dof) =
      eig.eigenvectors() * raised.asDiagonal() * eig.eigenvectors().transpose();
}

// Bias or ramp: the parity projected on gyro j's direction over the history kept (at most kHistory epochs,
// the fault's onset inside it) is explained by a step f·[t ≥ t_m] or by a ramp r·(t − t_m)₊, each with its
// best change time t_m. In units of the normalized parity, each fit removes G = (Σ x·u)²/Σ u² of the squared
// sum (u the model's shape; a change time before the history gives a constant or a line a + b·t); the kind is
// the model whose G is larger by design::drift_margin_sigma2; an offset without a trend (slope below 3σ) is a
// bias that began before the history; otherwise `unknown` (a step seen shortly after a ramp began fits both).
// Without parity (three gyros) the data cannot tell: unknown.
FaultKind Isolator::classify_drift(int id, std::int64_t index, GyroMask active, SubsetCache& subsets,
                                   EvidenceRows& rows) const {
  // The kind's row: G_step − G_ramp against the margin (NaN, JSON null, where there is no history to fit).
  const auto named = [&](FaultKind kind, double step_less_ramp) {
    rows.add(stated(EvidenceSource::kDriftShape, static_cast<std::uint8_t>(id),
                    kind == FaultKind::kUnknown ? RowVerdict::kNoCall : RowVerdict::kConsistent,
                    step_less_ramp, design::drift_margin_sigma2, 1));
    return kind;
  };
  const double no_fit = std::numeric_limits<double>::quiet_NaN();
  const Subset& s = subsets.get(active);
  if (!s.observable || s.dof < 1) return named(FaultKind::kUnknown, no_fit);
  const double w_norm = s.parity.col(id - 1).norm();
  const std::int64_t first = std::max<std::int64_t>(index - kHistory + 1, 0);
  double p[kMaxGyros];
  int n = 0;
  const std::int64_t t0 = time_of(first);
  for (std::int64_t k = first; k <= index; ++k) {
    const auto slot = static_cast<std::size_t>(k % kHistory);
    if ((hist_valid_[slot] & active) != active) continue;
    (void)apply_parity(s, active, &hist_y_[slot * static_cast<std::size_t>(n_)], 1.0, p);
    double proj = 0.0;
    for (int r = 0; r < s.dof; ++r) proj += s.parity(r, id - 1) / w_norm * p[r] * subsets.sqrt_period();
    drift_x_[static_cast<std::size_t>(n)] = proj;
    drift_t_[static_cast<std::size_t>(n)] = ns_to_seconds(hist_ns_[slot] - t0);
    ++n;
  }
  if (n < design::drift_min_epochs) return named(FaultKind::kUnknown, no_fit);
  // Suffix sums from the change sample m on: Σx, Σx·t, Σt, Σt², count.
  double sx = 0.0, sxt = 0.0, st = 0.0, stt = 0.0;
  double g_step = 0.0, g_ramp = 0.0;
  for (int m = n - 1; m >= 0; --m) {
    const double x = drift_x_[static_cast<std::size_t>(m)];
    const double t = drift_t_[static_cast<std::size_t>(m)];
    sx += x;
    sxt += x * t;
    st += t;
    stt += t * t;
    const double count = n - m;
    if (count < 3) continue;
    g_step = std::max(g_step, sx * sx / count);
    const double num = sxt - t * sx;                        // Σ x·(t_k − t_m)
    const double den = stt - 2.0 * t * st + count * t * t;  // Σ (t_k − t_m)²
    if (den > 0.0) g_ramp = std::max(g_ramp, num * num / den);
  }
  // A drift that began before the history: a constant (the step from m = 0) or a line a + b·t.
  const double g_const = sx * sx / n;
  const double sxx_t = stt - st * st / n;
  const double slope_gain = sxx_t > 0.0 ? (sxt - st * sx / n) * (sxt - st * sx / n) / sxx_t : 0.0;
  g_ramp = std::max(g_ramp, g_const + slope_gain);
  const double step_less_ramp = g_step - g_ramp;
  if (step_less_ramp > design::drift_margin_sigma2) return named(FaultKind::kBias, step_less_ramp);
  if (-step_less_ramp > design::drift_margin_sigma2) return named(FaultKind::kRamp, step_less_ramp);
  // An offset through the whole history with no trend in it (slope below 3σ): a bias that began before.
  if (slope_gain < design::drift_no_trend_sigma2 && g_const > design::drift_margin_sigma2)
    return named(FaultKind::kBias, step_less_ramp);
  return named(FaultKind::kUnknown, step_less_ramp);
}

Eigen::Vector3d Isolator::fault_angle(int id, std::int64_t from_index, std::int64_t index, GyroMask active,
                                      SubsetCache& subsets) const {
  // Each epoch's parity, fitted with a fault of gyro `id` alone: q = W·y = f·w (w its column), f = wᵀq/|w|².
  // Its rate error H*(:, id)·f acted over the step to that epoch.
  const Subset& s = subsets.get(active);
  if (!s.observable || s.dof < 1 || !has_gyro(active, id)) return Eigen::Vector3d::Zero();
  const auto w = s.parity.col(id - 1);  // a view: no copy
  const double w2 = std::max(w.squaredNorm(), 1e-300);
  double q[kMaxGyros];
  double sum = 0.0;  // [rad] Σ |f_k|·Δt_k
  for (std::int64_t k = std::max({from_index, index - kHistory + 2, std::int64_t{1}}); k <= index; ++k) {
    const auto slot = static_cast<std::size_t>(k % kHistory);
    if ((hist_valid_[slot] & active) != active) continue;
    (void)apply_parity(s, active, &hist_y_[slot * static_cast<std::size_t>(n_)], 1.0, q);
    double wq = 0.0;
    for (int r = 0; r < s.dof; ++r) wq += w[r] * q[r];
    sum += std::abs(wq / w2) * ns_to_seconds(hist_ns_[slot] - time_of(k - 1));
  }
  return s.pinv.col(id - 1).cwiseAbs() * sum;
}

}  // namespace tetra::fdi::detail
