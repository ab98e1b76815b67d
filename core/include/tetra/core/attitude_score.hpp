#pragma once
// Scoring an estimated attitude against the simulator's truth (`tetra score`, docs/score.md).
//
// Inputs (docs/interfaces.md §2.4 and docs/sim.md):
//   attitude  time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros[,sigma_x_deg,sigma_y_deg,
//             sigma_z_deg,bias_1_dps..bias_N_dps]   (tetra replay --attitude)
//   truth     time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps                      (tetra sim --truth)
// Columns are found by name; others are ignored.
//
// Error: the rotation from the true to the estimated body frame, as a rotation vector in the body frame,
//   e_B = log(q_true_RBᵀ ⊗ q_est_RB)   [deg]   (q_est = q_true ⊗ exp(e_B/2): a small rotation of the body).
// Matching: each attitude row takes the truth row whose time is within `time_tolerance_s` of its own;
// failing that, the truth interpolated (slerp) between the two rows around it; a row before the first
// or after the last truth row (by more than the tolerance) is not scored and counted.
// Uncertainty: the per-axis 1σ columns when the attitude file has them (NEES = Σ_a (e_a/σ_a)², 3 dof),
// else the total sigma_deg (normalized error² |e|²/σ², expectation 1 since σ² = σx² + σy² + σz²). An
// epoch whose sigma is 0 or NaN (nothing stated) is left out of NEES and of the σ-fractions, and counted.
// Integrated angle about an axis u (seed Fig. 7 left side): Σ_k u·ω_k·(t_k − t_{k−1}) over each file's own
// rows (the rate of a row times the interval that ends at it), from the attitude and the truth rates.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/quaternion.hpp"
#include "tetra/core/result.hpp"

namespace tetra {

//! One file's rows (attitude or truth).
struct AttitudeSeries {
  std::string source;                        //!< file name for messages
  std::vector<double> time_s;                //!< [s] strictly increasing
  std::vector<Quaternion> q_RB;              //!< body → reference, unit norm
  std::vector<Eigen::Vector3d> rate_B_dps;   //!< [deg/s] rate columns
  std::vector<double> sigma_deg;             //!< [deg] total 1σ; empty for truth
  std::vector<Eigen::Vector3d> sigma_B_deg;  //!< [deg] per-axis 1σ; empty when the file has none
  std::vector<std::size_t> lines;            //!< 1-based file line of each row
};

//! Reads an attitude file (`with_sigma`: sigma_deg required, per-axis sigma when present) or a truth
//! file. Bad input names the file, line and column: a missing column, a time not increasing, a
//! quaternion whose norm differs from 1 by more than 1e-3, a non-finite number, a negative sigma.
Result<AttitudeSeries> read_attitude_series(const std::string& path, bool with_sigma);
//! The same from text (tests); `source` names it in messages.
Result<AttitudeSeries> parse_attitude_series(std::string_view text, const std::string& source,
                                             bool with_sigma);

struct ScoreOptions {
  double time_tolerance_s = 1e-6;                     //!< [s] rows this close in time are the same epoch
  Eigen::Vector3d axis_B = Eigen::Vector3d::UnitY();  //!< unit axis of the integrated angle
};

//! One scored epoch (for the plot and the statistics).
struct ScoredEpoch {
  double time_s = 0.0;                                    //!< [s] the attitude row's time
  Eigen::Vector3d error_B_deg = Eigen::Vector3d::Zero();  //!< [deg] e_B
  Eigen::Vector3d sigma_B_deg = Eigen::Vector3d::Zero();  //!< [deg] per-axis 1σ (NaN without columns)
  double sigma_deg = 0.0;                                 //!< [deg] total 1σ
};

struct AttitudeScore {
  std::vector<ScoredEpoch> epochs;                          //!< every scored attitude row, in time order
  std::size_t exact_matches = 0;                            //!< rows with a truth row within the tolerance
  std::size_t interpolated = 0;                             //!< rows scored against interpolated truth
  std::size_t outside_truth = 0;                            //!< rows before or after the truth: not scored
  bool per_axis_sigma = false;                              //!< the per-axis 1σ columns were used
  Eigen::Vector3d rms_B_deg = Eigen::Vector3d::Zero();      //!< [deg] RMS of each component of e_B
  Eigen::Vector3d max_abs_B_deg = Eigen::Vector3d::Zero();  //!< [deg] largest |e_a|
  double rms_total_deg = 0.0;                               //!< [deg] RMS of |e_B|
  double max_total_deg = 0.0;                               //!< [deg] largest |e_B|
  double final_total_deg = 0.0;                             //!< [deg] |e_B| at the last scored row
  std::size_t sigma_epochs = 0;                             //!< epochs with a stated (positive) sigma
  std::size_t no_sigma_epochs = 0;                          //!< scored epochs with sigma 0 or NaN
  int nees_dof = 3;                                         //!< 3 with per-axis sigma, 1 with the total sigma
  double mean_nees = 0.0;  //!< mean of Σ(e_a/σ_a)² (3 dof) or |e|²/σ² (expectation 1)
  //! Fractions of the sigma epochs within 1, 2, 3σ: per axis (|e_a| ≤ kσ_a; NaN without per-axis sigma)
  //! and for the total angle (|e| ≤ kσ_total).
  std::array<Eigen::Vector3d, 3> within_B{};
  std::array<double, 3> within_total{};
  Eigen::Vector3d angle_B_deg = Eigen::Vector3d::Zero();        //!< [deg] integrated rate per body axis
  Eigen::Vector3d truth_angle_B_deg = Eigen::Vector3d::Zero();  //!< [deg] the same from the truth rates
  double angle_axis_deg = 0.0;        //!< [deg] integrated rate about ScoreOptions::axis_B
  double truth_angle_axis_deg = 0.0;  //!< [deg] the same from the truth
};

//! Scores `attitude` against `truth`. Bad input when no attitude row falls within the truth's time span,
//! or about an option (Error::subject "axis_B": not a unit vector; "time_tolerance_s": negative).
Result<AttitudeScore> score_attitude(const AttitudeSeries& attitude, const AttitudeSeries& truth,
                                     const ScoreOptions& options = {});

//! Σ u·ω_k·(t_k − t_{k−1}) over the rows [deg] (the rectangle rule of the seed experiment).
double integrated_angle_deg(const AttitudeSeries& series, const Eigen::Vector3d& axis_B);

}  // namespace tetra
