// Non-negative weighted least-squares fit of the IEEE Std 952 terms to an Allan curve.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Dense>

#include "tetra/core/allan.hpp"

namespace tetra::allan {

const char* term_symbol(int term) {
  static constexpr const char* kSymbols[kTermCount] = {"Q", "N", "B", "K", "R"};
  return term >= 0 && term < kTermCount ? kSymbols[term] : "?";
}

double term_basis(int term, double tau_s) {
  switch (term) {
    case kQ:
      return 3.0 / (tau_s * tau_s);
    case kN:
      return 1.0 / tau_s;
    case kB:
      return 2.0 * std::numbers::ln2 / std::numbers::pi;
    case kK:
      return tau_s / 3.0;
    case kR:
      return tau_s * tau_s / 2.0;
    default:
      return 0.0;
  }
}

NoiseType term_noise_type(int term) {
  switch (term) {
    case kQ:
      return NoiseType::kWhitePhase;
    case kN:
      return NoiseType::kWhiteRate;
    case kB:
      return NoiseType::kFlickerRate;
    default:
      return NoiseType::kRandomWalkRate;
  }
}

double NoiseFit::model_avar(double tau_s) const {
  double sum = 0.0;
  for (int k = 0; k < kTermCount; ++k) {
    const double v = value[static_cast<std::size_t>(k)];
    sum += v * v * term_basis(k, tau_s);
  }
  return sum;
}

namespace {

using Coefficients = std::array<double, kTermCount>;  // σ² coefficients Q², N², B², K², R²
constexpr int kAllTerms = (1 << kTermCount) - 1;

std::vector<const AdevPoint*> usable_points(std::span<const AdevPoint> points) {
  std::vector<const AdevPoint*> used;
  for (const AdevPoint& p : points) {
    if (p.terms > 0 && p.adev > 0.0 && std::isfinite(p.adev) && p.edf > 0.0) used.push_back(&p);
  }
  return used;
}

// The weighted least-squares system a·c = b, its columns scaled to unit norm (col_norm: the scales).
struct WeightedSystem {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  Eigen::VectorXd col_norm;
};

// Rows scaled by √(edf/2)/σ²: the residual of a row is the error of the model in units of the
// standard deviation of the variance estimate (Var s² = 2σ⁴/edf for a χ² estimate). σ² is the
// previous fit's model where given, else the measured value.
WeightedSystem weighted_system(const std::vector<const AdevPoint*>& used, const NoiseFit* weights_from) {
  const auto rows = static_cast<Eigen::Index>(used.size());
  WeightedSystem sys{Eigen::MatrixXd(rows, kTermCount), Eigen::VectorXd(rows), Eigen::VectorXd(kTermCount)};
  for (Eigen::Index i = 0; i < rows; ++i) {
    const AdevPoint& p = *used[static_cast<std::size_t>(i)];
    const double avar = p.adev * p.adev;
    const double model = weights_from != nullptr ? weights_from->model_avar(p.tau_s) : 0.0;
    const double w = std::sqrt(0.5 * p.edf) / (model > 0.0 ? model : avar);
    for (int k = 0; k < kTermCount; ++k) sys.a(i, k) = w * term_basis(k, p.tau_s);
    sys.b(i) = w * avar;
  }
  // Column scaling: the basis functions span many decades.
  for (int k = 0; k < kTermCount; ++k) {
    sys.col_norm(k) = sys.a.col(k).norm();
    if (sys.col_norm(k) > 0.0) sys.a.col(k) /= sys.col_norm(k);
  }
  return sys;
}

// Exact NNLS for five unknowns: the optimum is the unconstrained least-squares solution on its own
// support, so the best feasible subset solution is the optimum. `allowed` limits the terms.
// `interrupt` (optional): polled before each subset (a QR over every point).
Coefficients nnls(const WeightedSystem& sys, int allowed, Interrupt* interrupt) {
  const Eigen::Index rows = sys.a.rows();
  const auto all = static_cast<std::size_t>(rows);
  double best_cost = sys.b.squaredNorm();
  Eigen::VectorXd best = Eigen::VectorXd::Zero(kTermCount);
  for (int mask = 1; mask < (1 << kTermCount); ++mask) {
    if ((mask & ~allowed) != 0) continue;
    if (interrupt_requested(interrupt, all, all)) break;
    std::vector<int> cols;
    for (int k = 0; k < kTermCount; ++k) {
      if ((mask & (1 << k)) != 0) cols.push_back(k);
    }
    const auto nc = static_cast<Eigen::Index>(cols.size());
    if (nc > rows) continue;
    Eigen::MatrixXd sub(rows, nc);
    for (Eigen::Index j = 0; j < nc; ++j) sub.col(j) = sys.a.col(cols[static_cast<std::size_t>(j)]);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(sub);
    if (qr.rank() < nc) continue;
    const Eigen::VectorXd coef = qr.solve(sys.b);
    if ((coef.array() <= 0.0).any()) continue;
    const double cost = (sub * coef - sys.b).squaredNorm();
    if (cost < best_cost) {
      best_cost = cost;
      best.setZero();
      for (Eigen::Index j = 0; j < nc; ++j) best(cols[static_cast<std::size_t>(j)]) = coef(j);
    }
  }
  // Back to σ² coefficients (Q², N², B², K², R²).
  Coefficients c{};
  for (int k = 0; k < kTermCount; ++k) {
    c[static_cast<std::size_t>(k)] = sys.col_norm(k) > 0.0 ? std::max(0.0, best(k) / sys.col_norm(k)) : 0.0;
  }
  return c;
}

double model_of(const Coefficients& c, double tau_s) {
  double sum = 0.0;
  for (int k = 0; k < kTermCount; ++k) sum += c[static_cast<std::size_t>(k)] * term_basis(k, tau_s);
  return sum;
}

// Where each term dominates (fit's dominant_from_s/to_s); returns the dominant term of each point (-1: none).
std::vector<int> mark_dominant(const std::vector<const AdevPoint*>& used, const Coefficients& coeff,
                               NoiseFit& fit) {
  std::vector<int> largest(used.size(), -1);
  for (std::size_t i = 0; i < used.size(); ++i) {
    double best = 0.0;
    for (int k = 0; k < kTermCount; ++k) {
      const double contribution = coeff[static_cast<std::size_t>(k)] * term_basis(k, used[i]->tau_s);
      if (contribution > best) {
        best = contribution;
        largest[i] = k;
      }
    }
    if (largest[i] < 0) continue;
    const auto kl = static_cast<std::size_t>(largest[i]);
    if (fit.dominant_from_s[kl] == 0.0) fit.dominant_from_s[kl] = used[i]->tau_s;
    fit.dominant_to_s[kl] = used[i]->tau_s;
  }
  return largest;
}

// Observed: the model re-fitted without the term leaves the 95 % confidence interval of the
// measured variance at some τ where the term dominates — the other terms cannot stand in for it.
void mark_observed(const WeightedSystem& sys, const std::vector<const AdevPoint*>& used,
                   const std::vector<int>& largest, NoiseFit& fit, Interrupt* interrupt) {
  for (int k = 0; k < kTermCount; ++k) {
    if (fit.dominant_from_s[static_cast<std::size_t>(k)] == 0.0) continue;
    const Coefficients without = nnls(sys, kAllTerms & ~(1 << k), interrupt);
    for (std::size_t i = 0; i < used.size() && !fit.observed[static_cast<std::size_t>(k)]; ++i) {
      if (i % 16 == 0 && interrupt_requested(interrupt, used.size(), used.size())) return;
      if (largest[i] != k) continue;
      const AdevPoint& p = *used[i];
      const double avar = p.adev * p.adev;
      const double lower95 = avar * p.edf / chi2_quantile(0.975, p.edf);
      const double upper95 = avar * p.edf / chi2_quantile(0.025, p.edf);
      const double alt = model_of(without, p.tau_s);
      if (alt < lower95 || alt > upper95) fit.observed[static_cast<std::size_t>(k)] = true;
    }
  }
}

}  // namespace

NoiseFit fit_noise_terms(std::span<const AdevPoint> points, const NoiseFit* weights_from,
                         Interrupt* interrupt) {
  NoiseFit fit;
  const std::vector<const AdevPoint*> used = usable_points(points);
  fit.points_used = static_cast<int>(used.size());
  if (used.empty()) return fit;
  const WeightedSystem sys = weighted_system(used, weights_from);
  const Coefficients coeff = nnls(sys, kAllTerms, interrupt);
  for (int k = 0; k < kTermCount; ++k)
    fit.value[static_cast<std::size_t>(k)] = std::sqrt(coeff[static_cast<std::size_t>(k)]);
  const std::vector<int> largest = mark_dominant(used, coeff, fit);
  mark_observed(sys, used, largest, fit, interrupt);
  return fit;
}

}  // namespace tetra::allan
