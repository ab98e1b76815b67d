#pragma once
// A common drift below the detectors (docs/fdi.md, "A common drift below the detectors"): every gyro's bias
// moving together — a warm-up, each gyro following the temperature by its own coefficient — is a body-rate
// error the parity cannot see (its common part) and the bias model does not expect. With a reference it shows
// in the innovations as a mean: the filter's attitude error lags the drift. The reference's own bias test
// (reference_consistency.hpp) sees the same mean over reference_bias_window_s W, and cannot tell a drift of
// the gyros from a bias of the reference; so, while the gyros vouch for their attitude (parity over the
// active set, no episode open), the drift is matched first, at a lower level than a rejection — a match opens
// a model and decides nothing:
//
//   mean test  over W (the reference's bias block) and over 4W (here, a slower drift): the weighted mean
//              innovation's Σ_a (Σ z_a/S_aa)²/Σ 1/S_aa > χ²₃(1 − p_m)
//
// (p_m = the budget's kReferenceBiasMatch share per sample). A match opens every active gyro's slow bias c_i
// to a random walk of K_i² + λ·q_i [rad²/s³] (Mekf::open_bias_model), q_i = K_i² + 2σ_GM,i²/T_c + N_i²/T_c²
// the model's own wander per second: a body-rate error b = 2·z̄/T grown within the window T is a random walk
// of |b|²/T (T, while matches persist, from the first sample of the series' first match: what a block shows
// may be an error the filter still carries from before the block), and λ is at least ρ
// (design::block_match_ratio) times that over q_i — and at least ρ times its last value, so a drift that goes
// on opens the model further at every match. A mean that persists, the model opened (a match within the long
// window of the last), asks for ρ times more at each match: once the λ a match would set exceeds a working
// unit's wander (design::reference_max_wander_ratio) the mean is the reference's, and its bias test rejects
// it as before. The match is kept (the models only open) until a reset or an exclusion; each match is a
// noise_model event.

#include <algorithm>
#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "tetra/core/units.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

class Mekf;
struct GyroNoiseModel;

//! A common drift matched at this sample.
struct DriftFinding {
  double statistic = 0.0;  //!< [-] the mean test's χ²₃
  double threshold = 0.0;  //!< [-] χ²₃(1 − p_m)
  double ratio = 0.0;      //!< [-] λ, the bias random walk's variance over the model's wander q
};

class ReferenceBiasMatch {
 public:
  explicit ReferenceBiasMatch(const PipelineConfig& config);

  void reset();    //!< nothing matched, the window empty
  void restart();  //!< the window empty (a gap, an episode, a match); what is matched kept

  //! One reference sample the filter uses at `now_ns`, before its update, while the gyros vouch: its
  //! innovation `z_rad` with covariance `S`, over the gyros of `active`. The long window's mean test; a match
  //! opens `filter`'s bias models and is returned.
  std::optional<DriftFinding> observe(std::int64_t now_ns, const Eigen::Vector3d& z_rad,
                                      const Eigen::Matrix3d& S, GyroMask active, Mekf& filter);
  //! The mean `mean_rad` [rad] over `span_s` [s] matched as a drift (the reference's bias block, or the long
  //! window): every active gyro's slow bias opened; false (nothing opened) when it may not be a drift of
  //! working gyros (may_explain).
  bool match_mean(std::int64_t now_ns, const Eigen::Vector3d& mean_rad, double span_s, GyroMask active,
                  Mekf& filter);
  //! The λ a match at `now_ns` of a mean that needs `needed` would set: at least ρ times the last match's
  //! while the mean persists (the last match within the long window), at least ρ once it has not.
  double next_ratio(double needed, std::int64_t now_ns) const {
    return std::max(needed, design::block_match_ratio * (persists(now_ns) ? ratio_ : 1.0));
  }
  //! [s] the span a mean judged over `span_s` up to `now_ns` may have grown in under Hdrift: while a match
  //! persists, since the first sample the series' first match judged (the error a block shows may be one the
  //! filter still carries from before it; a block just restarted does not make the drift fast).
  double drift_span_s(double span_s, std::int64_t now_ns) const {
    return persists(now_ns) ? std::max(span_s, ns_to_seconds(now_ns - seen_from_ns_)) : span_s;
  }
  //! Whether a mean that needs `needed` may be matched as a drift of working gyros: the λ its match would
  //! set at most design::reference_max_wander_ratio (a mean that persists with the model opened asks for ρ
  //! times more at each match, and ends the reference's).
  bool may_explain(double needed, std::int64_t now_ns) const {
    return next_ratio(needed, now_ns) <= design::reference_max_wander_ratio;
  }
  //! λ·q_i ≥ ρ·|b|²/T: the ratio the mean `mean_rad` over `span_s` needs (+∞ without a span or a wander).
  static double needed_ratio(const Eigen::Vector3d& mean_rad, double span_s, GyroMask active,
                             const Mekf& filter);
  double threshold() const { return threshold_; }  //!< χ²₃(1 − p_m)
  bool matched() const { return matched_; }
  double ratio() const { return ratio_; }

 private:
  void open(GyroMask active, Mekf& filter) const;  //!< every active gyro's random walk at λ·q_i
  //! The last match is within the long window of `now_ns`.
  bool persists(std::int64_t now_ns) const {
    return last_match_ns_ >= 0 && now_ns - last_match_ns_ <= long_window_ns_;
  }
  //! [rad²/s³] q_i, the model's own wander per second: K² + 2σ_GM²/T_c + N²/T_c².
  static double wander(const GyroNoiseModel& m);

  double threshold_ = 0.0;                         //!< χ²₃(1 − p_m)
  std::int64_t long_window_ns_ = 0;                //!< 4W
  std::int64_t start_ns_ = -1;                     //!< the long window's first sample
  Eigen::Vector3d sw_ = Eigen::Vector3d::Zero();   //!< [1/rad²] per axis Σ 1/S_aa
  Eigen::Vector3d swz_ = Eigen::Vector3d::Zero();  //!< [1/rad] per axis Σ z_a/S_aa
  bool matched_ = false;
  std::int64_t last_match_ns_ = -1;  //!< the last match (-1: none since the reset)
  std::int64_t seen_from_ns_ = -1;   //!< the first sample the first match of the persisting series judged
  double ratio_ = 1.0;               //!< λ
};

}  // namespace tetra::fdi::detail
