#pragma once
// A calibration that does not describe the unit (docs/fdi.md, "A calibration that does not describe the
// unit"). Scale factors or axes off make the parity follow the body rate: p_k = p̄ + M·(ω_k − ω̄) + n_k. Over
// each block of design::motion_fit_block_s the gyro set's normalized parity is fitted to the measured rate,
// and the fit is judged per hypothesis: H0 (M within the calibration's stated tolerance), Hi (M what gyro i
// alone makes: its scale factor with four gyros, any error of its own from five on), Hcal (any M). Two blocks
// in a row with H0 and every Hi rejected name a mismatch: the unit's calibration is wrong in several gyros at
// once, which no exclusion mends. It then stands (for the gyro set), and exclusions whose evidence a
// calibration's error can make are withheld; a gyro's own signal still excludes it.

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "evidence_rows.hpp"
#include "subset_cache.hpp"

namespace tetra::fdi::detail {

class CalibrationFit {
 public:
  //! Forgets the block, the streak and a standing mismatch (a reset of the pipeline).
  void reset();
  //! One epoch of gyro set `mask`'s normalized parity `p` (s.dof values, the parity as measured) at the
  //! measured body rate ω [rad/s], at `now_ns`. A new set restarts the fit. True when this epoch closed a
  //! block whose rows name a mismatch for the first time (rows(): that block's).
  bool record(const Eigen::VectorXd& p, const Subset& s, GyroMask mask, const Eigen::Vector3d& omega_rad_s,
              std::int64_t now_ns, const SubsetCache& cache, const PipelineConfig& config);
  //! The parity's whitening changed (the noise model widened): the block starts again at the next epoch; the
  //! streak and a standing mismatch are kept.
  void restart_block() { restart_pending_ = true; }
  //! A mismatch stands for the gyro set in use.
  bool mismatch() const { return mismatch_; }
  //! The last block's rows (H0, each Hi of the set, Hcal).
  const EvidenceRows& rows() const { return rows_; }
  //! The last block's χ² of the fit under H0.
  double statistic() const { return h0_statistic_; }
  //! The parity was judged outside an episode: the unit has a fault-free history, so a detection has an
  //! onset a calibration's error does not make.
  void judged_nominal() { seen_nominal_ = true; }
  //! The Hcal rows an isolation's decision carries when `evidence` is one a calibration's error can make (not
  //! a gyro's own signal): consistent by the last block's fit while a mismatch stands, and consistent by the
  //! opening detection's statistic (`episode`'s first row) while the parity has been beyond its threshold
  //! since the first epoch (no fault-free history: no onset tells a fault from the calibration's error).
  void add_hcal_rows(EvidenceSource evidence, const EvidenceRows* episode, EvidenceRows& rows) const;

 private:
  void restart(const Subset& s, GyroMask mask, const Eigen::Vector3d& omega_rad_s, std::int64_t now_ns);
  void accumulate(const Eigen::VectorXd& p, int dof, const Eigen::Vector3d& omega_rad_s);
  //! The block's rows written into rows_; true when they name a mismatch (arbitrate_calibration).
  bool judge_block(const Subset& s, GyroMask mask, const SubsetCache& cache, const PipelineConfig& config);
  //! z = vec((ω − ω̄)ᵀ(p − p̄)) and its covariance S under H0 (noise, stated tolerance, wander).
  void moments(const Subset& s, GyroMask mask, const SubsetCache& cache, const PipelineConfig& config);
  //! The residual χ² of z once `basis`'s columns are fitted (none: H0), and its degrees of freedom.
  double residual(const Eigen::MatrixXd& basis, int columns, int& dof);
  //! [-] the parity's variance about the block's fit, per axis and epoch, at least 1 (z_ and Ω_c known).
  double noise_scale() const;

  GyroMask mask_ = 0;
  int dof_ = 0;
  std::int64_t start_ns_ = 0;
  double epochs_ = 0.0;
  Eigen::Matrix3d sum_ww_ = Eigen::Matrix3d::Zero();   //!< Σ ω ωᵀ [rad²/s²]
  Eigen::Vector3d sum_w_ = Eigen::Vector3d::Zero();    //!< Σ ω
  Eigen::Vector3d sum_dev_ = Eigen::Vector3d::Zero();  //!< Σ |ω − ω_first| per axis (the wander's reach)
  Eigen::Vector3d first_w_ = Eigen::Vector3d::Zero();
  Eigen::MatrixXd sum_wp_;  //!< 3×d Σ ω pᵀ
  Eigen::VectorXd sum_p_;   //!< d Σ p
  double sum_pp_ = 0.0;     //!< Σ |p|² (the parity's own spread: a unit noisier than stated)
  // Scratch of the block's judgement, sized once per gyro set (a block allocates nothing).
  Eigen::Matrix3d omega_c_ = Eigen::Matrix3d::Zero();
  Eigen::VectorXd z_;
  Eigen::MatrixXd cov_;
  Eigen::MatrixXd tolerance_;
  Eigen::MatrixXd basis_;
  Eigen::MatrixXd whitened_basis_;
  Eigen::VectorXd whitened_z_;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver_;
  int streak_ = 0;
  bool mismatch_ = false;
  bool seen_nominal_ = false;
  bool restart_pending_ = false;
  double h0_statistic_ = 0.0;
  double h0_threshold_ = 0.0;
  int h0_dof_ = 0;
  EvidenceRows rows_;
};

}  // namespace tetra::fdi::detail
