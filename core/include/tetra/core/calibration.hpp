#pragma once
// Turntable calibration of a redundant gyro package (seed paper, Kuga et al., eqs. 4–11).
//
// Model (docs/interfaces.md §1): g_i = s_i · (h_i · ω_B) + β_i + η_i, with g [V], s [V/(deg/s)], β [V], ω_B
// [deg/s] including the Earth rate, h_i a unit vector in B. Both estimators solve for x_i = s_i·h_i (the
// seed's h̃_i/K_i) and β_i by linear least squares, then apply the unit-norm constraint (seed eq. 8): s_i =
// |x_i|, h_i = x_i / |x_i|.
//
// The body rate of every sample comes from the encoder angles, never from a table of nominal rates:
// per sequence, the rotating gimbal's unwrapped angle is fitted by a straight line (its slope is the
// gimbal rate), the other gimbal must stay fixed, and
//   ω_B(t) = turntable_rate_B(inner(t), inner_dot, outer_dot) + C_LB(t)ᵀ · ω_e^L      (frames.hpp).
//
// Estimators:
//   kSixteen — the seed's procedure: per-sequence means ḡ(j), ω̄_B(j); pair differences
//              Δḡ(k) = ḡ(2k−1) − ḡ(2k) = x · (ω̄(2k−1) − ω̄(2k)) solved by least squares for x (eqs. 5–7);
//              then the bias (eq. 10) either with the Earth rate projected into B per sequence
//              (BiasModel::kBody: β = mean_j(ḡ(j) − x·ω̄_B(j))) or literally as the seed's eq. 11
//              (BiasModel::kSeed: β = mean_j ḡ(j) − x·ω_e^L, lab-frame Earth rate, table rates assumed to
//              cancel). 1σ: the per-sequence standard deviation of the mean (scatter of each sample around
//              the model within its sequence, / √n) propagated linearly through every step.
//   kBatch   — one least-squares fit of g_i(t) = x_i · ω_B(t) + β_i over every sample; 1σ from the residual
//              covariance σ̂²·(AᵀA)⁻¹ (white residuals assumed).
// With a noise model (CalibrationOptions::noise) both 1σ also carry the correlated noise: the covariance
// of the sequence means that bias instability and rate random walk cause (correlated over the whole log,
// so it does not average down like white noise), propagated through the same linear maps. Without it,
// a unit with bias instability gets 1σ several times too small (docs/calibration.md, "Are the 1σ honest?").
// Both report, per gyro, the residual RMS over samples and over sequence means.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/result.hpp"
#include "tetra/core/turntable_log.hpp"
#include "tetra/core/turntable_rows.hpp"

namespace tetra {

enum class CalibrationMethod { kSixteen, kBatch };
enum class BiasModel { kBody, kSeed };
enum class Gimbal { kInner, kOuter };

const char* to_string(CalibrationMethod method);  //!< "sixteen-position" / "batch" (calibration file names)
const char* to_string(BiasModel model);           //!< "body" / "seed"
const char* to_string(Gimbal gimbal);             //!< "inner" / "outer"

//! Tolerances used to interpret the encoder angles. Defaults suit a rate table with arc-second encoders.
struct TurntableTolerances {
  double fixed_span_deg = 0.05;         //!< [deg] a gimbal whose angle moves less than this is "fixed"
  double min_turn_deg = 1.0;            //!< [deg] a rotating gimbal must turn at least this much
  double max_rate_departure_deg = 0.5;  //!< [deg] rotating angle's largest departure from its line fit
  double pair_angle_match_deg = 0.1;    //!< [deg] fixed angles of the two sequences of a pair must agree
  int min_rows_per_sequence = 3;        //!< rows needed to fit a rate and a scatter
};

//! Motion of one sequence of the rotation plan, as derived from the encoders.
struct SequenceMotion {
  int sequence = 0;            //!< plan index (1-based)
  std::size_t first_row = 0;   //!< index of its first row in the log
  std::size_t row_count = 0;   //!< number of rows
  std::size_t first_line = 0;  //!< 1-based file lines of its first and last rows
  std::size_t last_line = 0;
  double first_time_s = 0.0;  //!< [s] times of its first and last rows
  double last_time_s = 0.0;
  Gimbal rotating = Gimbal::kInner;  //!< the gimbal that turns
  double rate_dps = 0.0;             //!< [deg/s] fitted rate of the rotating gimbal
  double turned_deg = 0.0;           //!< [deg] signed angle turned (last − first, unwrapped)
  double fixed_angle_deg = 0.0;      //!< [deg] mean angle of the fixed gimbal, in (−180, 180]
  Eigen::Vector3d table_rate_B_dps = Eigen::Vector3d::Zero();  //!< [deg/s] mean table rate in B
  Eigen::Vector3d earth_rate_B_dps = Eigen::Vector3d::Zero();  //!< [deg/s] mean Earth rate in B
  Eigen::Vector3d rate_B_dps() const { return table_rate_B_dps + earth_rate_B_dps; }  //!< [deg/s] ω̄_B
};

//! The log interpreted: sequences in plan order with their mean outputs. The body rate of a row is
//! recomputed from its sequence's motion and its encoder angles when needed, never stored per row.
struct BodyRateCache;  // calibration's own: the body rates once computed (core/src/calibration_rows.hpp)

struct TurntableMotion {
  std::string source;                     //!< file name for messages
  double latitude_deg = 0.0;              //!< [deg]
  std::size_t rows = 0;                   //!< rows of the log
  double start_time_s = 0.0;              //!< [s] time of the log's first row
  std::vector<SequenceMotion> sequences;  //!< sorted by plan index; pairs (2k−1, 2k) adjacent
  Eigen::MatrixXd g_mean_V;               //!< [V] M×N mean output of every gyro over each sequence
  //! The body rate of every row, written to a temporary file by the first pass that needs them and read
  //! back by the later ones (24 bytes a row, on disk); shared by copies of the motion.
  std::shared_ptr<BodyRateCache> rate_cache;
};

//! Interprets the encoder angles: groups rows by sequence (each sequence contiguous), unwraps angles,
//! finds the rotating gimbal and its rate, checks pairs (2k−1, 2k: same gimbal, opposite rates, same
//! fixed angle) and that the pairs excite all three body axes. Errors are bad input naming file and line.
//! Three passes over the rows; memory proportional to the number of sequences, not of rows.
Result<TurntableMotion> analyze_turntable(const TurntableRows& rows, double latitude_deg,
                                          const TurntableTolerances& tolerances = {});
Result<TurntableMotion> analyze_turntable(const TurntableLog& log, double latitude_deg,
                                          const TurntableTolerances& tolerances = {});

struct CalibrationOptions {
  CalibrationMethod method = CalibrationMethod::kSixteen;
  BiasModel bias_model = BiasModel::kBody;  //!< used by kSixteen only
  std::string unit = "tetra-1";             //!< written to the calibration file
  //! The unit's noise model per gyro (e.g. from `tetra allan`), for the 1σ only: empty = white noise
  //! within a sequence assumed; otherwise one entry per gyro, whose bias instability B and rate random
  //! walk K add the covariance of the sequence means they cause (correlated_noise.hpp).
  std::vector<GyroNoise> noise;
  double bias_instability_correlation_s = 100.0;  //!< [s] T_c of the Gauss–Markov model of B
};

//! How well a calibration explains the turntable data.
struct CalibrationFit {
  //! [V] M×N: mean over sequence j of (g_i − s_i h_i·ω_B − β_i).
  Eigen::MatrixXd sequence_residual_V;
  Eigen::VectorXd sample_rms_V;    //!< [V] per gyro: RMS of the residual over every sample
  Eigen::VectorXd sequence_rms_V;  //!< [V] per gyro: RMS of the sequence-mean residuals
};

//! Residuals of any calibration with the same number of gyros on the interpreted log.
//! One pass over the rows.
Result<CalibrationFit> evaluate_calibration(const TurntableRows& rows, const TurntableMotion& motion,
                                            const Calibration& calibration);
Result<CalibrationFit> evaluate_calibration(const TurntableLog& log, const TurntableMotion& motion,
                                            const Calibration& calibration);

struct CalibrationResult {
  Calibration calibration;  //!< estimates with their 1σ (GyroCalibration::sigma set)
  CalibrationFit fit;       //!< residuals of the estimate
  //! [V] M×N: 1σ of each sequence mean (scatter about the fitted model / √n); the input of kSixteen's σ.
  Eigen::MatrixXd sequence_sigma_mean_V;
};

//! Calibrates from an interpreted log (the log itself supplies the samples): kSixteen from the sequence
//! means and one pass for the scatter, kBatch in two passes (normal equations, then residuals); one more
//! for the fit. Memory proportional to the number of sequences, not of rows.
Result<CalibrationResult> calibrate(const TurntableRows& rows, const TurntableMotion& motion,
                                    const CalibrationOptions& options);
Result<CalibrationResult> calibrate(const TurntableLog& log, const TurntableMotion& motion,
                                    const CalibrationOptions& options);

}  // namespace tetra
