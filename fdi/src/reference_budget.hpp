#pragma once
// What the reference's own specification states but its samples cannot show: a slowly varying error (a
// thermo-elastic bias, a low-spatial-frequency error) of 1σ `reference_bias_arcsec` per axis, and a time
// stamp late by up to `reference_latency_max_s`. The filter follows either within its noise (docs/fdi.md,
// "Reference consistency", Limits): once the attitude has been tied to the reference it carries the error,
// and no test of the samples can tell. The published sigma carries the stated budget in quadrature instead:
// σ_β per axis, and for the latency the rotation over τ_max at the largest body rate of the recent reference
// updates, |ω_a|·τ_max (the offset a late reference shows at a rate ω is ω·τ). Both zero by default: the
// budget is what the user states, never a guess of the pipeline's.

#include <Eigen/Core>

#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

class ReferenceBudget {
 public:
  //! The budget of `config` (reference_bias_arcsec, reference_latency_max_s); the largest body rate of the
  //! updates is forgotten over reference_window_s (the filter's own memory of an offset is shorter).
  explicit ReferenceBudget(const PipelineConfig& config);
  //! No reference used since (a start): no budget. (An operator's reset keeps the attitude, so the budget.)
  void reset();
  //! A reference sample was used (initialized, accepted, re-initialized) at `time_s` [s] while the body
  //! turned at `omega_B_rad_s` [rad/s].
  void used(double time_s, const Eigen::Vector3d& omega_B_rad_s);
  //! The reference was rejected for a step of `step_rad` [rad] (0: another reason, nothing learned).
  void learn(double step_rad) { learned_rad_ += step_rad; }
  //! A drift was matched while the reference had pulled the attitude by `pull_rad` [rad] over the block.
  void learn_ambiguity(double pull_rad) { ambiguous_rad_ += pull_rad; }
  //! [rad] the attitude error the reference's bias may have left where a drift was matched (0: none).
  double ambiguous_rad() const { return ambiguous_rad_; }
  //! [rad] per axis: the budget's 1σ, zero before the first sample used or with an empty budget.
  Eigen::Vector3d sigma_rad() const;
  bool active() const { return used_ && (bias_rad_ > 0.0 || latency_max_s_ > 0.0 || learned_rad_ > 0.0); }

 private:
  double bias_rad_ = 0.0;
  double latency_max_s_ = 0.0;
  double hold_s_ = 30.0;
  bool used_ = false;
  double learned_rad_ = 0.0;    //!< [rad] the steps the reference has shown
  double ambiguous_rad_ = 0.0;  //!< [rad] Σ|D| of the drift matches
  double last_s_ = 0.0;
  Eigen::Vector3d rate_held_rad_s_ = Eigen::Vector3d::Zero();  //!< [rad/s] per axis, decaying peak of |ω|
};

}  // namespace tetra::fdi::detail
