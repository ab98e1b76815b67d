#include "parity_bias_match.hpp"

#include <algorithm>
#include <cmath>

#include "block_match.hpp"
#include "mekf.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi::detail {

namespace {}  // namespace

ParityBiasMatch::ParityBiasMatch(const PipelineConfig& config, int gyro_count)
    : false_alarm_(allocated_probability(config, BudgetTest::kParityBlockMatch)),
      sum_wnu_(static_cast<std::size_t>(gyro_count), 0.0),
      sum_w2_(static_cast<std::size_t>(gyro_count), 0.0),
      cusum_(static_cast<std::size_t>(gyro_count), 0.0),
      excess_(static_cast<std::size_t>(gyro_count), 0.0),
      block_excess_(static_cast<std::size_t>(gyro_count), 0.0),
      walk_(static_cast<std::size_t>(gyro_count), 0.0),
      last_f_(static_cast<std::size_t>(gyro_count), 0.0),
      last_var_(static_cast<std::size_t>(gyro_count), 0.0),
      block_f_(static_cast<std::size_t>(gyro_count), 0.0),
      block_var_(static_cast<std::size_t>(gyro_count), 0.0),
      innovation_(Eigen::VectorXd::Zero(std::max(gyro_count - 3, 1))),
      projection_(Eigen::VectorXd::Zero(gyro_count)) {}

void ParityBiasMatch::reset() {
  restart();
  matched_ = false;
  std::fill(excess_.begin(), excess_.end(), 0.0);
  std::fill(walk_.begin(), walk_.end(), 0.0);
}

void ParityBiasMatch::restart() {
  mask_ = 0;
  block_start_ns_ = -1;
  block_epochs_ = 0;
  std::fill(sum_wnu_.begin(), sum_wnu_.end(), 0.0);
  std::fill(sum_w2_.begin(), sum_w2_.end(), 0.0);
  std::fill(cusum_.begin(), cusum_.end(), 0.0);
  std::fill(last_var_.begin(), last_var_.end(), 0.0);
}

void ParityBiasMatch::release(Mekf& filter) {
  const bool was = matched_;
  reset();
  quiet_blocks_ = 0;
  if (!was) return;
  for (int id = 1; id <= static_cast<int>(excess_.size()); ++id) filter.clear_bias_model(id);
}

void ParityBiasMatch::forget(int id) {
  const auto k = static_cast<std::size_t>(id - 1);
  excess_[k] = 0.0;
  walk_[k] = 0.0;
  cusum_[k] = 0.0;
}

std::optional<BlockFinding> ParityBiasMatch::observe(std::int64_t now_ns, const Subset& s,
                                                     const Eigen::VectorXd& p, double sqrt_period,
                                                     Mekf& filter) {
  if (s.dof < 1 || !s.observable) return std::nullopt;
  if (s.mask != mask_) {  // other gyros: statistics afresh (a matched gyro keeps its bias model)
    restart();
    mask_ = s.mask;
  }
  if (block_start_ns_ < 0) block_start_ns_ = now_ns;
  const int n = static_cast<int>(sum_wnu_.size());
  // ν = p − √T·W·(ĉ + ĝ): the parity the filter's bias estimates do not explain (element by element, as
  // the vector expression was; the columns are the parity matrix's own, d rows each).
  const int d = s.dof;
  double* nu = innovation_.data();
  for (int r = 0; r < d; ++r) nu[r] = p[r];
  for (int i = 0; i < n; ++i) {
    if (!has_gyro(s.mask, i + 1)) continue;
    const double* w = s.parity.col(i).data();
    const double c = sqrt_period * filter.bias_rad_s(i + 1);
    for (int r = 0; r < d; ++r) nu[r] -= w[r] * c;
  }
  const Eigen::Map<const Eigen::VectorXd> innovation(nu, d);
  for (int i = 0; i < n; ++i) {
    if (!has_gyro(s.mask, i + 1)) continue;
    const auto k = static_cast<std::size_t>(i);
    const double a = sqrt_period * s.parity_col_norm[i];
    sum_wnu_[k] += sqrt_period * (d == 1 ? s.parity(0, i) * nu[0] : s.parity.col(i).head(d).dot(innovation));
    sum_w2_[k] += a * a;
  }
  ++block_epochs_;
  if (now_ns - block_start_ns_ < seconds_to_ns(design::parity_bias_block_s)) return std::nullopt;
  auto found = close_block(s, ns_to_seconds(now_ns - block_start_ns_), filter);
  block_start_ns_ = now_ns;
  block_epochs_ = 0;
  return found;
}

std::optional<BlockFinding> ParityBiasMatch::close_block(const Subset& s, double block_s, Mekf& filter) {
  // A block of n epochs stands for n of the per-epoch false-alarm probability p, and each gyro's CUSUM is one
  // test. The threshold ln(1/(p·n·|S|)) stops at ln 2 where p·n·|S| passes 1/2 (at the largest share: p above
  // 4e-7 for four gyros at 10 Hz, 4e-8 at 100 Hz); there the blocks open the models often, which costs sigma
  // and noise_model events but decides nothing, and the budget's row states the rate.
  const double threshold = block_cusum_threshold(false_alarm_ * block_epochs_ * tetra::gyro_count(s.mask));
  const int n = static_cast<int>(sum_wnu_.size());
  const Eigen::MatrixXd& P = filter.covariance();
  std::optional<BlockFinding> first;  // the gyro whose CUSUM is furthest beyond the threshold
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!has_gyro(s.mask, i + 1) || !(sum_w2_[k] > 0.0)) continue;
    // v_i: the filter's bias uncertainty seen the way f̂_i sees it, f̂_i ← Σ_j (w_iᵀ·w_j/|w_i|²)·e_j.
    const double wi2 = s.parity_col_norm[i] * s.parity_col_norm[i];
    for (int j = 0; j < n; ++j)
      projection_[j] =
          has_gyro(s.mask, j + 1) ? s.parity.col(i).head(s.dof).dot(s.parity.col(j).head(s.dof)) / wi2 : 0.0;
    double v = 0.0;
    for (int j = 0; j < n; ++j) {
      if (projection_[j] == 0.0) continue;
      for (int l = 0; l < n; ++l) {
        if (projection_[l] == 0.0) continue;
        const double cov =
            P(3 + j, 3 + l) + P(3 + j, 3 + n + l) + P(3 + n + j, 3 + l) + P(3 + n + j, 3 + n + l);
        v += projection_[j] * cov * projection_[l];
      }
    }
    // The filter's innovations are white while its model holds: its bias uncertainty v enters each epoch's
    // innovation afresh, so the block's mean carries v/n of it, not v (the error is corrected every epoch).
    const double f = sum_wnu_[k] / sum_w2_[k];  // [rad/s] the block's mean error
    const double predicted =
        white_ratio_ / sum_w2_[k] + std::max(v, 0.0) / block_epochs_;  // [rad²/s²] its variance
    const double u = f * f / predicted;
    sum_wnu_[k] = 0.0;
    sum_w2_[k] = 0.0;
    cusum_[k] = block_cusum_step(cusum_[k], u, 1.0);
    if (cusum_[k] > threshold && (!first || cusum_[k] > first->statistic))
      first = BlockFinding{i + 1, cusum_[k], threshold, u};
    // The excess under gyro i's hypothesis (the error is gyro i's alone): kept per gyro, used once matched.
    block_excess_[k] = f * f - predicted;
    block_f_[k] = f;
    block_var_[k] = predicted;
  }
  const bool alarm = first.has_value();
  if (matched_ && !alarm) {
    bool quiet = true;
    for (int i = 0; i < n; ++i)
      quiet = quiet && !(has_gyro(s.mask, i + 1) && cusum_[static_cast<std::size_t>(i)] > 0.0);
    quiet_blocks_ = quiet ? quiet_blocks_ + 1 : 0;
    if (quiet_blocks_ >= design::parity_bias_quiet_blocks) {
      release(filter);
      return std::nullopt;
    }
  }
  const bool begun = alarm && !matched_;
  matched_ = matched_ || alarm;
  // Which gyro the parity's blocks cannot always tell (their columns are not orthogonal): every gyro of the
  // set takes the excess its own hypothesis gives, so sigma covers each single-gyro explanation.
  for (int i = 0; i < n && matched_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!has_gyro(s.mask, i + 1)) continue;
    excess_[k] = std::max(excess_[k], block_excess_[k]);
    // How fast it moves: the change from the last block beyond both blocks' predicted variances, per second
    // of block (covariance matching on differences: a random walk of K² moves a block mean by K²·T).
    if (last_var_[k] > 0.0) {
      const double step = block_f_[k] - last_f_[k];
      walk_[k] = std::max(walk_[k], (step * step - block_var_[k] - last_var_[k]) / block_s);
    }
    filter.open_bias_model(i + 1, excess_[k], walk_[k]);
  }
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    last_f_[k] = block_f_[k];
    last_var_[k] = has_gyro(s.mask, i + 1) ? block_var_[k] : 0.0;
  }
  return begun ? first : std::nullopt;
}

}  // namespace tetra::fdi::detail
