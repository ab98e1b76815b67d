#pragma once
// Allan-variance noise characterization of gyro rate data (IEEE Std 952-1997 Annex C; NIST SP 1065).
//
// The overlapping Allan variance of rate samples y_i (i = 0..n−1, interval τ0) at τ = m·τ0 is computed
// from the angle x_k = τ0·Σ_{i<k} y_i:
//   σ²(τ) = Σ_i (x_{i+2m} − 2x_{i+m} + x_i)² / (2 τ² · terms),
// which costs O(n) per τ. A term is used only when all 2m rate samples it spans are present (a
// cumulative count of present samples tells this in O(1)), so gaps never bias the estimate; they only
// reduce the number of terms.
//
// Confidence intervals come from the χ² distribution with the equivalent degrees of freedom of the
// noise type that dominates at each τ (allan_stats.hpp). The noise type is taken from the fitted model
// below, iterated until it no longer changes (at most three passes).
//
// The five IEEE 952 terms are fitted to σ²(τ) by non-negative weighted least squares:
//   σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²τ/3 + R²τ²/2,
// each point weighted by edf/(2σ⁴), the inverse variance of a χ²-distributed variance estimate, σ²
// taken from the previous pass's model (iteratively reweighted; the measured value on the first
// pass). With gaps the EDF is summed over the runs of consecutive samples.
// A term is reported as observed only if, at some τ where it is the largest contribution to the
// fitted model, the model re-fitted WITHOUT that term leaves the 95 % confidence interval of the
// measured variance — i.e. the other terms cannot stand in for it and the data need it. Otherwise it
// is "not observed" (seed Table 6: "NO").

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tetra/core/allan_stats.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/interrupt.hpp"
#include "tetra/core/result.hpp"

namespace tetra::allan {

// --- error subjects (Error::subject.name of this header's errors; a command maps them to options) ---

inline constexpr const char* kSubjectTaus =
    "taus";  //!< the averaging times (parse_tau_spec, AllanOptions::taus)
inline constexpr const char* kSubjectGyros =
    "gyros";  //!< LogAllanOptions::gyros; value: the id not in the log
//! One gyro of several could not be analysed: the others can be, when analysed without it
//! (LogAllanOptions::gyros); the message names the log and the gyro.
inline constexpr const char* kSubjectOtherGyros = "other_gyros";
inline constexpr const char* kSubjectNoiseUpdate = "noise_update";  //!< update_calibration_noise's output
inline constexpr const char* kSubjectKalibr = "kalibr";  //!< kalibr_gyro_noise's output (allan_kalibr.hpp)

// --- averaging times ---------------------------------------------------------------------------

enum class TauSpacing {
  kDefault,  //!< about ten per decade: m = round(10^(j/10)), duplicates removed
  kOctave,   //!< m = 1, 2, 4, 8, ...
  kDecade,   //!< m = 1, 2, 5, 10, 20, 50, ...
  kAll,      //!< every m = 1 .. n/2 (O(n²): refused when it would take too long)
  kList,     //!< the averaging times in `list_s`, rounded to whole multiples of τ0
};

struct TauSpec {
  TauSpacing spacing = TauSpacing::kDefault;
  std::vector<double> list_s;  //!< [s] for kList
};

//! Parses `octave`, `decade`, `all`, `default`, or a comma list of averaging times in seconds.
//! Non-positive or non-numeric times are an error.
Result<TauSpec> parse_tau_spec(std::string_view text);

//! The averaging factors m (τ = m·τ0), increasing and distinct, for `samples` rate samples.
//! Every m satisfies 1 ≤ m ≤ samples/2 (at least one term). A listed τ outside that range is an error.
Result<std::vector<std::int64_t>> averaging_factors(const TauSpec& spec, std::size_t samples, double tau0_s);

// --- sampling ----------------------------------------------------------------------------------

//! Places the epochs of a log on a uniform time grid.
struct SamplingGrid {
  double tau0_s = 0.0;             //!< [s] sampling interval: median of the time steps
  std::size_t slots = 0;           //!< grid length (epochs + missing epochs)
  std::size_t missing_epochs = 0;  //!< grid slots without a row (time steps of k·τ0, k ≥ 2)
  std::vector<std::size_t> slot;   //!< grid index of each epoch
};

//! Builds the grid from epoch times. Each time step must be within `tolerance`·τ0 of a whole
//! multiple k ≥ 1 of τ0 (k ≥ 2 leaves k − 1 missing epochs, handled as gaps); otherwise the sampling
//! is non-uniform and the error names the line. `lines` (optional) are file lines for messages.
Result<SamplingGrid> uniform_grid(std::span<const double> time_s, double tolerance, const std::string& source,
                                  std::span<const std::size_t> lines = {});

// --- overlapping Allan variance ----------------------------------------------------------------

struct AvarPoint {
  std::int64_t m = 0;      //!< averaging factor
  double tau_s = 0.0;      //!< [s] m·τ0
  double avar = 0.0;       //!< overlapping Allan variance [unit²]; NaN when terms == 0
  std::int64_t terms = 0;  //!< number of second differences used
};

//! Overlapping Allan variance at each averaging factor. `present` (same length as `rate`, or empty
//! for "all present") marks delivered samples; a NaN rate counts as not present. `interrupt` (optional)
//! is polled before each factor: once it asks to stop, the points computed so far are returned.
std::vector<AvarPoint> overlapping_avar(std::span<const double> rate, std::span<const std::uint8_t> present,
                                        double tau0_s, std::span<const std::int64_t> m_values,
                                        Interrupt* interrupt = nullptr);

// --- noise model -------------------------------------------------------------------------------

inline constexpr int kTermCount = 5;
enum Term : int { kQ = 0, kN = 1, kB = 2, kK = 3, kR = 4 };
//! "Q", "N", "B", "K", "R".
const char* term_symbol(int term);
//! f_k(τ) of σ²(τ) = Σ_k c_k f_k(τ), c = (Q², N², B², K², R²): 3/τ², 1/τ, 2 ln2/π, τ/3, τ²/2.
double term_basis(int term, double tau_s);
//! The noise type a term behaves like (rate ramp is treated as random-walk rate for the EDF).
NoiseType term_noise_type(int term);

//! One point of an Allan curve with its confidence interval.
struct AdevPoint {
  double tau_s = 0.0;                       //!< [s]
  double adev = 0.0;                        //!< overlapping Allan deviation [unit]
  double adev_lo = 0.0;                     //!< lower confidence bound [unit]
  double adev_hi = 0.0;                     //!< upper confidence bound [unit]
  std::int64_t terms = 0;                   //!< number of second differences
  double edf = 0.0;                         //!< equivalent degrees of freedom
  NoiseType noise = NoiseType::kWhiteRate;  //!< noise type assumed for the EDF
};

struct NoiseFit {
  std::array<double, kTermCount> value{};  //!< Q [unit·s], N [unit·√s], B [unit], K [unit/√s], R [unit/s]
  std::array<bool, kTermCount> observed{};           //!< term needed by the data (see file comment)
  std::array<double, kTermCount> dominant_from_s{};  //!< [s] first τ where the term dominates (0 if never)
  std::array<double, kTermCount> dominant_to_s{};    //!< [s] last τ where the term dominates (0 if never)
  int points_used = 0;                               //!< points that entered the fit
  //! Fitted σ²(τ) with every fitted term (observed or not).
  double model_avar(double tau_s) const;
  //! A term's value, or nullopt when it is not observed.
  std::optional<double> reported(int term) const {
    return observed[static_cast<std::size_t>(term)]
               ? std::optional<double>(value[static_cast<std::size_t>(term)])
               : std::nullopt;
  }
};

//! Non-negative weighted least-squares fit of the five terms to the points (exact: every subset of
//! terms is solved and the best one with all coefficients ≥ 0 kept), then the "observed" test.
//! Weights are edf/(2σ⁴) with σ² from `weights_from`'s model when given, else the measured value.
//! `interrupt` (optional) is polled between the subsets and every 16 points of the "observed" test (each
//! point reported as all done): once it asks to stop, the fit returned is unfinished.
NoiseFit fit_noise_terms(std::span<const AdevPoint> points, const NoiseFit* weights_from = nullptr,
                         Interrupt* interrupt = nullptr);

// --- whole analysis ----------------------------------------------------------------------------

inline constexpr double kOneSigmaConfidence = 0.682689492137086;  //!< erf(1/√2)

struct AllanOptions {
  TauSpec taus;                             //!< averaging times
  double confidence = kOneSigmaConfidence;  //!< two-sided confidence level of the intervals
  //! analyze_series polls it (optional, not owned) before each averaging time (τ done of the τ asked)
  //! and every 16 points of the intervals (reported as all τ done): when it asks to stop, the call returns
  //! interrupted(). The log analyses (analyze_gyro_log, analyze_gyro_log_file), which run gyros in parallel,
  //! ignore it.
  Interrupt* interrupt = nullptr;
};

struct AllanResult {
  double tau0_s = 0.0;              //!< [s]
  std::size_t samples = 0;          //!< rate samples on the grid (gaps included)
  std::size_t present_samples = 0;  //!< samples delivered and finite
  std::vector<AdevPoint> points;    //!< one per averaging time with at least one term
  //! [s] requested averaging times that could not be computed (gaps leave no window of 2m consecutive
  //! samples): reported in every output (CSV rows with adev nan and n 0, JSON, table), never dropped.
  std::vector<double> uncomputed_tau_s;
  NoiseFit fit;
};

//! Allan curve, confidence intervals and noise terms of one uniformly sampled rate series.
//! Errors: fewer than two present samples, bad confidence level, bad τ list.
Result<AllanResult> analyze_series(std::span<const double> rate, std::span<const std::uint8_t> present,
                                   double tau0_s, const AllanOptions& options);

struct GyroAllan {
  int id = 0;               //!< 1..N
  std::size_t absent = 0;   //!< samples not delivered (empty cells and missing epochs)
  std::size_t invalid = 0;  //!< samples delivered as NaN/inf
  AllanResult result;
};

struct LogAllanOptions {
  AllanOptions allan;
  double dt_tolerance = 0.05;  //!< [-] allowed deviation of a time step from k·τ0, relative to τ0
  std::vector<int> gyros;      //!< ids to analyse (1..N); empty: all
  const Calibration* calibration = nullptr;  //!< volts → deg/s as (g − bias)/scale; ignored for dps logs
};

struct LogAllan {
  std::string units;               //!< "deg/s" or "V"
  bool log_units_dps = false;      //!< the log itself was in deg/s ("# units=dps")
  double tau0_s = 0.0;             //!< [s]
  std::size_t epochs = 0;          //!< rows in the log
  std::size_t missing_epochs = 0;  //!< grid slots without a row
  std::vector<GyroAllan> gyros;
};

//! Analyses the gyros of a log. The error names the file (and line, where one is at fault).
Result<LogAllan> analyze_gyro_log(const GyroLog& log, const LogAllanOptions& options);

//! The same analysis, with the same results bit for bit, of a log file (CSV or HDF5) read block by
//! block: at most about 14 bytes per sample (the rate of each gyro as a double, turned into its
//! cumulative sum in place; the times; the grid slots), gyros analysed two at a time. The blocks and
//! arrays are anonymous memory mappings given back to the system as soon as they are consumed.
Result<LogAllan> analyze_gyro_log_file(const std::string& path, const LogAllanOptions& options);

// --- reports -----------------------------------------------------------------------------------

//! docs/interfaces.md §2.6 CSV: gyro,tau_s,adev,adev_lo,adev_hi,n.
std::string format_csv(const LogAllan& analysis);
//! docs/interfaces.md §2.6 JSON: {"units": ..., "gyros": [{"id", "Q", "N", "B", "K", "R"}]}, null = not
//! observed.
std::string format_json(const LogAllan& analysis,
                        const std::vector<std::pair<std::string, std::string>>& provenance = {});
//! A table like seed Table 6, in the input's units and (for deg/s) in deg/√h, deg/h, deg/h/√h, deg/h².
std::string format_table(const LogAllan& analysis);

//! Customary-unit factor of a term for deg/s-based values: Q deg → deg, N deg/√s → deg/√h (×60),
//! B deg/s → deg/h (×3600), K deg/s/√s → deg/h/√h (×216000), R deg/s² → deg/h² (×3600²).
double customary_factor(int term);

//! Writes the noise terms into a calibration's `noise:` sections (deg/s units required).
Status update_calibration_noise(Calibration& cal, const LogAllan& analysis);

}  // namespace tetra::allan
