#pragma once
// Isolation of a detected fault (docs/fdi.md, "Isolation"): the episode a detection opens, the history of
// calibrated rates, the onset test (window means before and after the CUSUM's change time against physically
// possible motion), the GLT for N ≥ 5, and the bias-or-ramp classification. It isolates only when exactly one
// single-gyro hypothesis explains the data; otherwise the episode ends `unisolated` or `cleared`.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "epoch_frame.hpp"
#include "gyro_series.hpp"
#include "parity_detector.hpp"
#include "subset_cache.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi::detail {

struct Episode {
  bool active = false;  //!< a fault is detected and not isolated
  bool declared_unisolated = false;
  std::int64_t detect_ns = 0;
  std::int64_t deadline_ns = 0;  //!< evidence is sought until then
  std::int64_t last_alarm_ns = 0;
  std::int64_t onset_index = 0;  //!< estimated first faulty epoch
  std::int64_t onset_ns = 0;
  DetectionTest test = DetectionTest::kNone;
  double statistic = 0.0;
};

//! What the episode concluded this epoch.
enum class Verdict : std::uint8_t { kNone, kIsolated, kUnisolated, kCleared };

class Isolator {
 public:
  Isolator(int n_gyros, const PipelineConfig& config);

  //! Keeps the epoch's calibrated rates for the onset test and the drift classification.
  void record(const EpochFrame& frame);
  //! A detection opens an episode (no-op when one is open). Returns true when it opened one.
  //! `omega_rad_s`: this epoch's measured body rate (the GLT's calibration term for the epochs before).
  bool open(const Detection& detection, std::int64_t now_ns, std::int64_t index, const Subset& s,
            const ParityDetector& detector, const Eigen::Vector3d& omega_rad_s);
  //! Every alarm, opening or not, keeps the episode alive.
  void alarmed(std::int64_t now_ns) { episode_.last_alarm_ns = now_ns; }
  //! The CUSUM saw this epoch: the GLT accumulates its measured parity and body rate [rad/s] while an
  //! episode is open.
  void accumulate(const Eigen::VectorXd& p, int dof, const Eigen::Vector3d& omega_rad_s);
  //! Seeks evidence for the open episode. `found` is set with kIsolated.
  Verdict decide(std::int64_t now_ns, std::int64_t index, GyroMask active, SubsetCache& subsets,
                 const GyroSeries& series, Isolation& found);
  //! Bias or ramp, from the parity projected on gyro `id` over the history (a step or a ramp from the best
  //! change time); unknown when neither fits clearly better, or without parity. The kind's one row
  //! (drift_shape, gyro `id`'s hypothesis) goes to `rows`: consistent when a kind is named, else no call.
  FaultKind classify_drift(int id, std::int64_t index, GyroMask active, SubsetCache& subsets,
                           EvidenceRows& rows) const;
  //! [rad] per axis: a bound of the attitude error a fault on gyro `id` caused from history epoch
  //! `from_index` to `index` while in the solution of `active`: Σ |H*(:, id)|·|f_k|·Δt_k, f_k the fault the
  //! epoch's parity puts on that gyro (every epoch of the full set kept in the history; zero without parity).
  Eigen::Vector3d fault_angle(int id, std::int64_t from_index, std::int64_t index, GyroMask active,
                              SubsetCache& subsets) const;
  //! Closes the episode (after a reconfiguration or an operator command).
  void close();

  const Episode& episode() const { return episode_; }
  //! The rows of the last `decide`: the onset test's per hypothesis (no call when a window it needs cannot be
  //! judged), or the GLT's when it runs (N ≥ 5: the onset test's are then dropped); empty before either can.
  const EvidenceRows& rows() const { return rows_; }
  //! [ns] time of a history epoch.
  std::int64_t time_of(std::int64_t index) const;
  //! [ns] time of epoch `onset_index`, or of the oldest epoch kept when it is older (`index`: this epoch).
  std::int64_t onset_time(std::int64_t onset_index, std::int64_t index) const {
    return time_of(std::max({onset_index, index - kHistory + 1, std::int64_t{0}}));
  }

 private:
  static constexpr int kHistory = 256;  //!< [epochs] history kept for the onset test
  int onset_test(std::int64_t index, GyroMask active, SubsetCache& subsets, const GyroSeries& series);
  //! The onset test's rows when a window it needs cannot be judged: H0 and every active gyro's hypothesis no
  //! call, the statistic the window's motion over its bound (> 1: the body turned beyond it there; NaN: the
  //! window before the onset is no longer kept). Returns 0 (no culprit).
  int no_call(GyroMask active, double ratio);
  //! Means of two history windows [b1, e1) and [b2, e2) into the pre/post scratch; their separation [s].
  double two_windows(std::int64_t b1, std::int64_t e1, std::int64_t b2, std::int64_t e2);
  //! 1: the change between the two windows' means seen by `mask` is a possible motion (within the
  //! acceleration bound over `separation_s` and the noise); 0: it is not; −1: cannot judge.
  //! `ratio`, when given: the change over its bound (NaN when it cannot judge).
  int motion_within_bound(GyroMask mask, double separation_s, SubsetCache& subsets, const GyroSeries& series,
                          double* ratio = nullptr) const;
  int glt_test(const Subset& s, const SubsetCache& subsets);
  //! r_i for every gyro i of `s`: the residual of m after the best fault along w_i, in the metric C⁻¹.
  void glt_residuals(const Subset& s, const Eigen::VectorXd& m, const Eigen::MatrixXd& cov, double* r) const;
  //! The GLT's baseline: the mean normalized parity and rate over the clean epochs before the onset kept in
  //! the history (all of `s`'s gyros valid), at most design::glt_baseline_max_epochs of them; none when fewer
  //! than design::glt_baseline_min_epochs are kept.
  void glt_baseline(std::int64_t index, const Subset& s, double sqrt_period);
  void baseline_noise(std::int64_t begin, std::int64_t end, const Subset& s, double sqrt_period);
  //! Window means of each gyro's rate over history epochs [b, e); returns the mean time offset from b [s].
  double window_means(std::int64_t b, std::int64_t e, std::vector<double>& mean,
                      std::vector<int>& count) const;
  double y_at(std::size_t slot, int i) const {
    return hist_y_[slot * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)];
  }

  int n_;
  const PipelineConfig& config_;
  Episode episode_;
  EvidenceRows rows_;
  Eigen::VectorXd glt_sum_;  //!< Σ p since the onset (d ≥ 2)
  int glt_n_ = 0;
  Eigen::Vector3d glt_omega_sum_ = Eigen::Vector3d::Zero();  //!< [rad/s] Σ ω since the onset
  bool glt_baseline_done_ = false;                           //!< the baseline was sought for this episode
  int glt_pre_n_ = 0;                                        //!< epochs of the baseline (0: none)
  Eigen::VectorXd glt_pre_;                                  //!< its mean normalized parity
  //! [σ²] the white noise's covariance the baseline shows (d×d in its top-left corner), at least the model's
  //! I
  Eigen::MatrixXd glt_noise_cov_;
  Eigen::Vector3d glt_omega_pre_ = Eigen::Vector3d::Zero();  //!< [rad/s] its mean rate
  std::vector<double> glt_y_pre_;                            //!< scratch: its mean rates per gyro
  std::vector<double> hist_y_;                               //!< kHistory×N [rad/s]
  std::vector<GyroMask> hist_valid_;
  std::vector<std::int64_t> hist_ns_;
  std::vector<double> mean_pre_, mean_post_;
  std::vector<int> n_pre_, n_post_;
  mutable std::vector<double> drift_x_;            //!< scratch of classify_drift: projected parity [σ]
  mutable std::vector<double> drift_t_;            //!< [s] its times
  mutable std::vector<Eigen::VectorXd> glt_mean_;  //!< scratch per parity dimension (never resized)
  mutable std::vector<Eigen::VectorXd> glt_w_;
  std::vector<Eigen::MatrixXd> glt_cov_;  //!< scratch per parity dimension: the mean's covariance
  mutable std::vector<Eigen::LDLT<Eigen::MatrixXd>> glt_ldlt_;  //!< and its factorization
};

}  // namespace tetra::fdi::detail
