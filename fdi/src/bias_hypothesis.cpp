#include "bias_hypothesis.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi::detail {

namespace {}  // namespace

BiasHypothesis::BiasHypothesis(const std::vector<GyroConstants>& constants) : bins_(kBins) {
  for (const auto& c : constants) {
    bias_sigma_rad_s_.push_back(c.bias_sigma_rad_s);
    quantization_rad_.push_back(c.quantization_rad);
  }
}

void BiasHypothesis::reset() {
  bin_count_ = 0;
  open_ = Bin{};
}

void BiasHypothesis::record(const Eigen::VectorXd& p, const Subset& s) {
  if (s.dof < 1) return;
  if (open_.mask != s.mask) open_ = Bin{0, s.mask, 0, {}};  // a partial bin of another set is dropped
  for (int r = 0; r < s.dof; ++r) open_.sum[static_cast<std::size_t>(r)] += p[r];
  ++open_.count;
}

void BiasHypothesis::close_bin(std::int64_t now_ns) {
  open_.end_ns = now_ns;
  bins_[static_cast<std::size_t>(bin_count_ % kBins)] = open_;
  ++bin_count_;
  open_ = Bin{0, open_.mask, 0, {}};
}

int BiasHypothesis::parity_mean(const Subset& s, std::int64_t from_ns, double sqrt_period) const {
  int n = 0;
  int contiguous = 0;  // bins summed: each may begin after a gap, where the quantization does not telescope
  for (int d = 0; d < s.dof; ++d) mean_[static_cast<std::size_t>(d)] = 0.0;
  for (int k = bin_count_ - 1; k >= std::max(0, bin_count_ - kBins); --k) {
    const Bin& b = bins_[static_cast<std::size_t>(k % kBins)];
    if (b.end_ns <= from_ns) break;
    if (b.mask != s.mask || b.count == 0) continue;
    n += b.count;
    ++contiguous;
    for (int d = 0; d < s.dof; ++d) mean_[static_cast<std::size_t>(d)] += b.sum[static_cast<std::size_t>(d)];
  }
  if (n == 0) return 0;
  const double period = sqrt_period * sqrt_period;
  for (int d = 0; d < s.dof; ++d) {
    const auto r = static_cast<std::size_t>(d);
    mean_[r] /= n;
    // White noise 1/n; the wandering bias; each gyro's calibrated offset (√T·W·c); its quantization
    // (e_end − e_start)/(nT) per contiguous run, var(e) = Q².
    double v = 1.0 / n + s.bias_wander_sigma * s.bias_wander_sigma;
    for (Eigen::Index i = 0; i < s.parity.cols(); ++i) {
      if (!has_gyro(s.mask, static_cast<int>(i) + 1)) continue;
      const double w2 = s.parity(d, i) * s.parity(d, i);
      const auto u = static_cast<std::size_t>(i);
      v += w2 * period * bias_sigma_rad_s_[u] * bias_sigma_rad_s_[u];
      v += w2 * 2.0 * quantization_rad_[u] * quantization_rad_[u] * contiguous / (double(n) * n * period);
    }
    var_[r] = v;
  }
  return n;
}

double BiasHypothesis::gain(int i, const Subset& s, const SpanDisagreement& span, double sqrt_period,
                            double& size) const {
  // Gyro i carries a fault of mean rate f over the span: the parity mean moves by √T·W(:, i)·f, its
  // disagreement with the reference by f·τ; every other gyro's stays zero. f from weighted least squares.
  double num = 0.0;
  double den = 0.0;
  for (int d = 0; d < s.dof; ++d) {
    const auto r = static_cast<std::size_t>(d);
    const double a = sqrt_period * s.parity(d, i - 1);
    num += a * mean_[r] / var_[r];
    den += a * a / var_[r];
  }
  const auto u = static_cast<std::size_t>(i - 1);
  if (has_gyro(span.gyros, i)) {
    const double var_e = span.sigma_rad[u] * span.sigma_rad[u];
    num += span.err_rad[u] * span.span_s / var_e;
    den += span.span_s * span.span_s / var_e;
  }
  size = den > 0.0 ? num / den : 0.0;
  return den > 0.0 ? num * num / den : 0.0;
}

BiasFit BiasHypothesis::best(const Subset& s, const SpanDisagreement& span, double sqrt_period,
                             EvidenceRows& rows) const {
  BiasFit fit;
  if (span.start < 0 || s.dof < 1 || parity_mean(s, span.start_ns, sqrt_period) < 2) return fit;
  // Everything the records hold (squared, in σ) and how much of it each gyro's fault explains.
  double total = 0.0;
  for (int d = 0; d < s.dof; ++d) {
    const auto r = static_cast<std::size_t>(d);
    total += mean_[r] * mean_[r] / var_[r];
  }
  int compared = 0;
  double g_best = -1.0, g_second = 0.0, size_best = 0.0;
  int best = 0;
  std::array<double, kMaxGyros> gains{};
  for (int i = 1; i <= static_cast<int>(s.parity.cols()); ++i) {
    if (!has_gyro(s.mask, i)) continue;
    if (has_gyro(span.gyros, i)) {
      const auto u = static_cast<std::size_t>(i - 1);
      total += span.err_rad[u] * span.err_rad[u] / (span.sigma_rad[u] * span.sigma_rad[u]);
      ++compared;
    }
    double size = 0.0;
    const double g = gain(i, s, span, sqrt_period, size);
    gains[static_cast<std::size_t>(i - 1)] = g;
    if (g > g_best) {
      g_second = std::max(g_second, g_best);
      g_best = g;
      size_best = size;
      best = i;
    } else {
      g_second = std::max(g_second, g);
    }
  }
  const int dof = s.dof + compared - 1;
  const double residual_limit = dof >= 1 ? chi2_threshold(design::bias_model_reject_probability, dof) : 0.0;
  const bool model = best != 0 && dof >= 1 && total - g_best <= residual_limit;
  for (int i = 1; i <= static_cast<int>(s.parity.cols()); ++i) {
    if (!has_gyro(s.mask, i)) continue;
    const auto h = static_cast<std::uint8_t>(i);
    rows.add(model ? judge(EvidenceSource::kBiasFit, h, g_best - gains[static_cast<std::size_t>(i - 1)], 0.0,
                           design::bias_hypothesis_margin_sigma2, 1)
                   : stated(EvidenceSource::kBiasFit, h, RowVerdict::kNoCall, total - g_best, residual_limit,
                            std::max(dof, 0)));
  }
  if (!model) return fit;
  return BiasFit{best, size_best, g_best - g_second};  // by how much it beats the others: the rows' to judge
}

std::optional<LedgerRow> BiasHypothesis::persists(int id, double sign, const Subset& s,
                                                  const SpanDisagreement& late, double sqrt_period) const {
  if (late.start < 0 || parity_mean(s, late.start_ns, sqrt_period) < 2) return std::nullopt;
  double size = 0.0;
  const double g = gain(id, s, late, sqrt_period, size);
  const bool there = size * sign > 0.0 && g >= design::bias_hypothesis_persist_sigma2;
  return stated(EvidenceSource::kBiasPersists, static_cast<std::uint8_t>(id),
                there ? RowVerdict::kConsistent : RowVerdict::kRejected, g,
                design::bias_hypothesis_persist_sigma2, 1);
}

}  // namespace tetra::fdi::detail
