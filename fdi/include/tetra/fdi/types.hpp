#pragma once
// Data exchanged by the fusion pipeline: input epochs, attitude output, health and FDI events
// (docs/interfaces.md §2.4, §2.5, §4). Plain data, no middleware: services/ converts these to and from DDS
// types, and `tetra replay` to and from files.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "tetra/core/geometry.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/fdi/ledger.hpp"

namespace tetra::fdi {

//! NOMINAL: all gyros, parity available. DEGRADED: a gyro excluded. SUSPECT: fault detected, not
//! isolated. LOST: fewer than 3 usable gyros, attitude not observable.
enum class Mode : std::uint8_t { kNominal, kDegraded, kSuspect, kLost };
const char* to_string(Mode mode);  // "NOMINAL", "DEGRADED", "SUSPECT", "LOST"

enum class FaultKind : std::uint8_t {
  kNone,
  kBias,
  kRamp,
  kScale,
  kStuck,
  kNoise,
  kSpike,
  kDropout,
  kInvalid,
  kUnknown
};
const char* to_string(FaultKind kind);  // "none", "bias", ..., "unknown"
std::optional<FaultKind> fault_kind_from_string(std::string_view text);

//! detected, isolated, unisolated (detected and the data cannot tell which gyro), reconfigured,
//! cleared, lost; and command (acknowledgement of an operator command — an addition to docs/interfaces.md
//! §2.5); fdi_unavailable / fdi_available: fault detection lost (no parity left and no recent reference) or
//! back (docs/fdi.md, "Reconfiguration and modes"); gap: no epoch for longer than `max_gap_s` (statistic: its
//! length [s]; docs/fdi.md, "Data path").
enum class EventType : std::uint8_t {
  kDetected,
  kIsolated,
  kUnisolated,
  kReconfigured,
  kCleared,
  kLost,
  kCommand,
  kFdiUnavailable,
  kFdiAvailable,
  kGap,                //!< no epoch for longer than max_gap_s (statistic: the gap's length [s])
  kReferenceRejected,  //!< the attitude reference failed a consistency test (why: ReferenceCheck)
  kReferenceAccepted,  //!< a rejected reference passed every test for reference_window_s: used again
  kReferenceLate,      //!< a reference stamped beyond the fusion horizon (statistic: how late [s]): left out
  kNoiseModel,  //!< the data show the noise model optimistic: a model opened to what they show (detail:
                //!< which)
  //! the parity follows the body rate as no single gyro's fault makes it: the calibration's scale factors
  //! and axes do not describe the unit (statistic: the motion fit's χ²); no exclusion while it stands
  kCalibrationMismatch
};
const char* to_string(EventType type);

//! The attitude reference's state (docs/fdi.md, "Reference consistency").
enum class ReferenceState : std::uint8_t {
  kAbsent,    //!< no sample within reference_window_s (or none yet)
  kAccepted,  //!< its samples update the filter
  kRejected   //!< failed a test: its samples are left out until consistent again
};
const char* to_string(ReferenceState state);  // "absent", "accepted", "rejected"

//! Why a reference was rejected.
enum class ReferenceCheck : std::uint8_t { kNone, kNis, kLag, kBias, kJump, kStep };
const char* to_string(ReferenceCheck check);  // "", "nis", "lag", "bias", "jump", "step"
//! The check named by `text` (as written by to_string); kNone for any other text.
ReferenceCheck reference_check_from_string(std::string_view text);

//! The test that raised a detection (or triggered an isolation).
//! kLevel: the CUSUM on the parity minus an open episode's held level (a new fault during the episode).
enum class DetectionTest : std::uint8_t { kNone, kChi2, kCusum, kSignature, kOnset, kReference, kLevel };
const char* to_string(DetectionTest test);  // "", "chi2", "cusum", "signature", "onset", "reference", "level"
//! The test named by `text` (as written by to_string); kNone for any other text.
DetectionTest detection_test_from_string(std::string_view text);

//! What told which gyro failed.
enum class Evidence : std::uint8_t {
  kNone,
  kInvalid,          //!< invalid samples for dropout_timeout_s
  kTimeout,          //!< absent for dropout_timeout_s
  kRepeated,         //!< identical raw values in a row
  kZero,             //!< identical raw values, all 0 V
  kVariance,         //!< robust noise level too low
  kNoiseLevel,       //!< robust noise level too high
  kRecurringSpikes,  //!< confirmed one-epoch outliers, noise otherwise normal
  kOnset,            //!< abrupt onset no physical motion explains
  kReference,        //!< attitude reference
  kGlt               //!< generalized likelihood test (N ≥ 5)
};
const char* to_string(Evidence evidence);  // "", "invalid", "timeout", "repeated", "zero", "variance", ...
//! The evidence named by `text` (as written by to_string); kNone for any other text.
Evidence evidence_from_string(std::string_view text);

//! Operator commands and their outcome (the acknowledgement).
enum class CommandVerb : std::uint8_t { kExclude, kReinstate, kReset };
const char* to_string(CommandVerb verb);  // "exclude", "reinstate", "reset"
enum class CommandOutcome : std::uint8_t {
  kDone,
  kNoSuchGyro,
  kAlreadyExcluded,
  kNotExcluded,
  kRefusedUnobservable  //!< the gyros left could not determine the attitude (`force` overrides)
};
const char* to_string(CommandOutcome outcome);  // "done", "rejected, no such gyro", ...
//! The outcome named by `text` (as written by to_string), if any.
std::optional<CommandOutcome> command_outcome_from_string(std::string_view text);

//! One input epoch: up to N raw samples taken at one sensor time, and an optional reference.
struct Epoch {
  std::int64_t stamp_ns = 0;                 //!< [ns] sensor time of the epoch
  std::vector<double> raw;                   //!< [V] (or [deg/s] when the log says units=dps), size N
  std::vector<std::uint8_t> present;         //!< size N; 0 = no sample delivered this epoch
  std::optional<Quaternion> reference_q_RB;  //!< attitude reference (e.g. star tracker), body → reference
  //! [ns] the reference's own time when it is not this epoch's: a reference delivered after the epoch of its
  //! stamp was fused, fused at its own time within `reference_horizon_s` (docs/fdi.md, "Late references")
  std::optional<std::int64_t> reference_stamp_ns = std::nullopt;
};

struct FdiEvent {
  std::int64_t stamp_ns = 0;  //!< [ns] time of the epoch that triggered the event
  EventType type = EventType::kDetected;
  //! 1..N: isolated gyro, the gyro a command named, or the gyro a detection names without excluding it
  //! (three gyros: its own noise level or the reference's innovations along its rate axis)
  std::optional<int> gyro;
  DetectionTest test = DetectionTest::kNone;                    //!< detected, unisolated, isolated: the test
  double statistic = std::numeric_limits<double>::quiet_NaN();  //!< detected: value of the test statistic
  FaultKind kind = FaultKind::kUnknown;                         //!< isolated: classified fault kind
  Evidence evidence = Evidence::kNone;                          //!< isolated: what told the gyro
  GyroMask gyros = 0;  //!< reconfigured / cleared / lost / command: the gyros used from now on
  std::optional<CommandVerb> command;              //!< command: the verb acknowledged
  CommandOutcome outcome = CommandOutcome::kDone;  //!< command: its outcome
  ReferenceCheck why = ReferenceCheck::kNone;  //!< reference_rejected (and a `reference` detection): the test
  std::string detail;                          //!< free text: e.g. the command acknowledged and its outcome
  //! detected, isolated, unisolated, cleared, reference_rejected: the ledger rows that decided it
  //! (ledger.hpp)
  std::vector<LedgerRow> ledger;

  //! command: refused (the outcome says why); nothing changed.
  bool refused() const { return type == EventType::kCommand && outcome != CommandOutcome::kDone; }
};

//! The gyro the arbiter's rule names from an event's ledger alone (its gyro hypotheses are the gyros that
//! were in use; a reference existed when an Href row is there), or 0: an `isolated` event's gyro is rebuilt
//! from it.
int ruling_of(const FdiEvent& event);
//! The arbiter's reference rule over an event's ledger alone (its gyro hypotheses the gyros in use): a
//! `reference_rejected` event's rows rebuild kReject, a `noise_model` event's kMatchDrift.
ReferenceDecision reference_ruling_of(const FdiEvent& event);
//! The arbiter's calibration rule over an event's ledger alone: a `calibration_mismatch` event's rows
//! rebuild true.
bool calibration_ruling_of(const FdiEvent& event);
//! A `noise_model` event's rows rebuild its step: the reference rule's kMatchDrift (a common drift), or the
//! parity's spread rejecting the stated noise (H0 of source parity_spread rejected).
bool noise_ruling_of(const FdiEvent& event);

//! One JSON object (one line, no newline) per docs/interfaces.md §2.5; `n_gyros` formats the `gyros` lists.
std::string to_json(const FdiEvent& event, int n_gyros);

enum class GyroState : std::uint8_t { kOk, kAbsent, kInvalid, kSuspect, kExcluded };
const char* to_string(GyroState state);  // "ok", "absent", "invalid", "suspect", "excluded"

struct GyroHealth {
  GyroState state = GyroState::kOk;
  FaultKind kind = FaultKind::kNone;  //!< why it is excluded or suspect
  double bias_rad_s = 0.0;            //!< [rad/s] the attitude filter's estimate of its bias (c + g)
  double bias_sigma_rad_s = 0.0;      //!< [rad/s] 1σ of that estimate
};

struct Counters {
  std::uint64_t epochs_accepted = 0;
  std::uint64_t epochs_rejected_time = 0;  //!< time not increasing (duplicate, backward, out of order)
  //! epochs stamped far from the stream's time (beyond 1000 sample periods; docs/fdi.md, "Per epoch"):
  //! dropped
  std::uint64_t epochs_time_outlier = 0;
  std::uint64_t samples_accepted = 0;
  std::uint64_t samples_invalid = 0;        //!< NaN, Inf or out of range
  std::uint64_t samples_absent = 0;         //!< no sample delivered
  std::uint64_t epochs_rejected_shape = 0;  //!< epoch with a sample count other than N
  std::uint64_t samples_outlier = 0;        //!< valid samples left out for one epoch (spike or onset)
  std::uint64_t spikes = 0;                 //!< confirmed one-epoch spikes (outliers that went away)
  std::uint64_t reference_accepted = 0;     //!< reference samples the attitude filter used
  std::uint64_t reference_rejected = 0;  //!< reference samples its χ² gate rejected or left out (rejected)
  std::uint64_t reference_reinitialized = 0;  //!< times a run of rejections set the attitude again
  std::uint64_t reference_invalid = 0;  //!< reference samples left out: not finite or norm not 1 within 1e-3
  std::uint64_t reference_delayed = 0;  //!< reference samples stamped before their epoch, fused at their time
  std::uint64_t reference_too_late = 0;  //!< reference samples stamped beyond the fusion horizon: left out
};

struct Health {
  std::int64_t stamp_ns = 0;
  Mode mode = Mode::kNominal;
  GyroMask used = 0;              //!< gyros in the current solution
  std::vector<GyroHealth> gyros;  //!< size N
  double parity_residual = 0.0;   //!< normalized parity residual (dimensionless, σ units)
  double chi2 = 0.0;              //!< instantaneous χ² statistic
  double cusum = 0.0;             //!< CUSUM statistic (largest of its branches)
  double chi2_threshold = 0.0;
  double cusum_threshold = 0.0;
  Counters counters;
  double reference_chi2 = 0.0;  //!< χ² (3 dof) of the last reference sample's innovation
  //! false: a new fault cannot be detected (the gyros used leave no parity and no reference came within
  //! reference_window_s); signatures of a single gyro (stuck, noise, dropout...) still run.
  bool fdi_available = true;
  ReferenceState reference_state = ReferenceState::kAbsent;  //!< the attitude reference's state
  //! [-] the reference's windowed NIS per degree of freedom (≈ 1 when consistent; 0 before any sample)
  double reference_nis = 0.0;
  //! [rad] per body axis: the integrity bound beside sigma (AttitudeEstimate::protection_level_rad)
  Eigen::Vector3d protection_level_rad = Eigen::Vector3d::Zero();
};

//! The estimate published every accepted epoch (docs/interfaces.md §2.4).
struct AttitudeEstimate {
  std::int64_t stamp_ns = 0;
  Quaternion q_RB = Quaternion::Identity();  //!< body → reference
  Eigen::Vector3d omega_BR_B_rad_s =
      Eigen::Vector3d::Zero();  //!< rate used for propagation (Earth rate removed in ground mode)
  Eigen::Vector3d sigma_rad = Eigen::Vector3d::Zero();  //!< 1σ attitude uncertainty per body axis
  Mode mode = Mode::kNominal;
  GyroMask gyros = 0;                   //!< gyros used
  std::vector<double> gyro_bias_rad_s;  //!< [rad/s] size N: the filter's estimate of each gyro's bias
  bool fdi_available = true;            //!< as Health::fdi_available: false = a new fault would go unseen
  //! [rad] per body axis: the error a single-gyro fault below the detection threshold can have caused since
  //! the last reference sample used (or the start), plus σ at integrity_risk; +∞ without parity (no
  //! integrity)
  Eigen::Vector3d protection_level_rad = Eigen::Vector3d::Zero();
};

}  // namespace tetra::fdi
