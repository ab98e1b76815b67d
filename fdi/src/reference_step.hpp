#pragma once
// The reference's step test (docs/fdi.md, "Reference consistency"): a reference whose error steps by b at
// sample j (a star tracker re-identifying, a thermal snap) shows in the innovations as b·g_k from j on, g the
// filter's absorption of an offset — g_j = 1, g_{k+1} = g_k·ρ_k, ρ_k = 1 − K_k per axis, K_k = P/S the
// attitude's gain at sample k (σ_ref²/S_aa = 1 − K). The filter takes the step into its attitude within a
// few 1/K samples, so no one sample and no long mean shows a step of a few σ_ref; the matched fit does. Over
// the last design::reference_step_samples samples, for every onset j, per axis the weighted fit z = c·g
// (a good reference's innovations have no mean; a drift's mean is the bias test's, judged first) gives
// ĉ = Σwgz/Σwg² (w = 1/S_aa) and, under a good reference (white innovations of covariance S), ĉ²·Σwg² is
// χ²₁. Two things a good reference does that can look like a step are allowed for:
//   - a calibration within calibration_error_sigmas of its stated σ turns the gyros' attitude by at most
//     β_a, its rate bound integrated over the window (SubsetCache::calibration_rate_bound, the bound sigma
//     integrates too): |ĉ_a| less that;
//   - a noisier unit or reference scales the innovations: each axis's term is divided by its residual
//     variance ratio r̂_a about the fit (when above 1), so the test sees a step's shape, `nis` the scale.
//   statistic = max_j Σ_a max(0, |ĉ_a| − β_a)²·Σwg² / max(1, r̂_a,j)  >  χ²₃(1 − p/M)
// (M onsets searched, p the budget's kReferenceCheck share: its union bound over the onsets is p per
// sample). The fit's ĉ and the share of it the filter has already taken, 1 − Π ρ, are what a rejection
// puts into the attitude's variance and the reference's budget (reference_budget.hpp).
//
// A step is the reference's (Href); the gyros' common drift (Hdrift: a warm-up) makes a rate error b from
// its onset on, which the innovations show as b·h_k: h_j = Δt_j, h_{k+1} = ρ_k·h_k + Δt_{k+1} (the error
// grows by b·Δt between samples, the filter takes K of it at each). Its fit per axis, b̂ = Σwhz/Σwh², reduces
// the innovations' χ² by (Σwhz)²/Σwh² as a step's fit does by (Σwgz)²/Σwg²; both are found for every onset
// by recursions from the newest sample back (h from j is Σ_{i≥j} Δt_i times the step's g from i).
// ramp_fit() gives the best of each over the onsets: when the step explains the innovations beyond the best
// ramp by less than the step test's own threshold, the step the test found may be a drift's.

#include <array>

#include <Eigen/Core>

#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

//! The best onset's fit over the window, among those whose statistic exceeds the level asked for (none:
//! statistic 0).
struct StepFit {
  double statistic = 0.0;  //!< [-] as in the header, χ²₃ under a good reference
  Eigen::Vector3d step_rad = Eigen::Vector3d::Zero();  //!< [rad] ĉ per axis
  Eigen::Vector3d absorbed = Eigen::Vector3d::Zero();  //!< [-] per axis the share the filter has taken
};

//! The window's best ramp beside its best step (the raw fits, without the calibration's allowance or the
//! residual scale): what tells a drift of the gyros from a step of the reference.
struct RampFit {
  double step_chi2 = 0.0;                                //!< [-] max over the onsets of Σ_a (Σwgz)²/Σwg²
  double ramp_chi2 = 0.0;                                //!< [-] max over the onsets of Σ_a (Σwhz)²/Σwh²
  Eigen::Vector3d rate_rad_s = Eigen::Vector3d::Zero();  //!< [rad/s] the best ramp's b̂ per axis
  double span_s = 0.0;  //!< [s] from the best ramp's onset to the newest sample
};

class ReferenceStep {
 public:
  explicit ReferenceStep(const PipelineConfig& config);

  void reset() { count_ = 0; }  //!< the window empty
  //! One sample: its innovation `z_rad` [rad], its covariance's diagonal `s_rad2` [rad²], the reference's
  //! variance `reference_var_rad2` [rad²] (the filter's gain is 1 − that over S), `calibration_rad` [rad]
  //! per axis the attitude error the calibration's tolerance allows since the previous sample, and
  //! `since_s` [s] the time since it.
  void add(const Eigen::Vector3d& z_rad, const Eigen::Vector3d& s_rad2, double reference_var_rad2,
           const Eigen::Vector3d& calibration_rad, double since_s);
  //! The best onset over the window beyond `level` (the test's threshold, or a lower one to see the
  //! statistic's distribution).
  StepFit evaluate(double level) const;
  //! The best step's and the best ramp's fits over the window (the header; none: zeros).
  RampFit ramp_fit() const;
  double threshold() const { return threshold_; }  //!< χ²₃(1 − p/M)

 private:
  struct Sample {                                               //!< per axis
    Eigen::Vector3d w = Eigen::Vector3d::Zero();                //!< [1/rad²] 1/S_aa
    Eigen::Vector3d wz = Eigen::Vector3d::Zero();               //!< [1/rad] w·z
    Eigen::Vector3d wzz = Eigen::Vector3d::Zero();              //!< [-] w·z²
    Eigen::Vector3d rho = Eigen::Vector3d::Zero();              //!< [-] 1 − K
    Eigen::Vector3d rho2 = Eigen::Vector3d::Zero();             //!< [-] ρ²
    Eigen::Vector3d calibration_rad = Eigen::Vector3d::Zero();  //!< [rad] allowed since the previous sample
    double since_s = 0.0;                                       //!< [s] Δt since the previous sample
  };
  const Sample& at(int k) const {  //!< k-th oldest sample of the window
    return ring_[static_cast<std::size_t>((head_ + kCapacity - count_ + k) % kCapacity)];
  }
  static constexpr int kCapacity = design::reference_step_samples;
  std::array<Sample, kCapacity> ring_{};
  int head_ = 0;   //!< where the next sample goes
  int count_ = 0;  //!< samples in the window
  double threshold_ = 0.0;
};

}  // namespace tetra::fdi::detail
