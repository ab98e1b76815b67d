#pragma once
// The pipeline's state and stages (Pipeline::Impl): the class the stage files share. pipeline.cpp runs one
// epoch and decides; pipeline_reference.cpp judges the attitude reference; pipeline_commands.cpp obeys the
// operator's commands and holds the public API.

#include "tetra/fdi/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "bias_hypothesis.hpp"
#include "calibration_fit.hpp"
#include "disagreement_trend.hpp"
#include "gyro_series.hpp"
#include "gyro_set.hpp"
#include "innovation_mean.hpp"
#include "isolator.hpp"
#include "mekf.hpp"
#include "outlier_gate.hpp"
#include "own_noise_level.hpp"
#include "parity_bias_match.hpp"
#include "parity_detector.hpp"
#include "parity_spread.hpp"
#include "protection_level.hpp"
#include "quadrature.hpp"
#include "rate_attitude.hpp"
#include "reference_bias_match.hpp"
#include "reference_budget.hpp"
#include "reference_consistency.hpp"
#include "reference_horizon.hpp"
#include "reference_monitor.hpp"
#include "reference_noise_match.hpp"
#include "reference_pull.hpp"
#include "stamp_judge.hpp"
#include "subset_cache.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"
#include "tetra/fdi/noise_defaults.hpp"

namespace tetra::fdi {

namespace detail {

inline Eigen::VectorXd bias_sigmas(const std::vector<GyroConstants>& constants) {
  Eigen::VectorXd b(static_cast<Eigen::Index>(constants.size()));
  for (std::size_t i = 0; i < constants.size(); ++i)
    b[static_cast<Eigen::Index>(i)] = constants[i].bias_sigma_rad_s;
  return b;
}

//! [ns] now − span, saturating at the earliest representable time (span ≥ 0).
inline std::int64_t pipeline_time_before_ns(std::int64_t now_ns, std::int64_t span_ns) {
  return now_ns >= std::numeric_limits<std::int64_t>::min() + span_ns
             ? now_ns - span_ns
             : std::numeric_limits<std::int64_t>::min();
}

}  // namespace detail

using namespace detail;

//! What a pipeline is created from, once validated: reset() creates the pipeline again from it.
struct PipelineInputs {
  PipelineConfig config;
  Calibration calibration;
  GyroGeometry geometry;
  std::vector<GyroConstants> constants;
};

class Pipeline::Impl {
 public:
  explicit Impl(const PipelineInputs& inputs)
      : Impl(inputs.config, inputs.calibration, inputs.geometry, inputs.constants) {}
  Impl(const PipelineConfig& config, const Calibration& cal, GyroGeometry geometry,
       std::vector<GyroConstants> constants)
      : config_(config),
        n_(cal.gyro_count()),
        subsets_(geometry, bias_sigmas(constants), config_, detector_noise(cal, config_)),
        bias_check_(constants),
        own_noise_(constants, config_),
        sample_spread_(allocated_probability(config_, BudgetTest::kParitySpread)),
        white_spread_(allocated_probability(config_, BudgetTest::kParitySpread)),
        blocks_(std::max(1, cal.gyro_count() - 3)),
        series_(constants, config_),
        gate_(n_, config_),
        detector_(n_, config_.clear_after_s),
        isolator_(n_, config_),
        reference_(cal.axes_B(), config_),
        gyro_set_(n_),
        attitude_(config_, noise_models(cal, series_, config_)),
        consistency_(config_),
        noise_match_(config_, n_),
        bias_match_(config_, n_),
        drift_match_(config_),
        protection_(config_),
        budget_(config_),
        innovation_mean_(config_.reference_window_s),
        horizon_(config_.reference_horizon_s),
        inputs_{config, cal, std::move(geometry), std::move(constants)} {
    frame_.resize(n_);
    found_.reserve(static_cast<std::size_t>(n_));
    own_named_.reserve(static_cast<std::size_t>(n_));
    held_parity_ = Eigen::VectorXd::Zero(std::max(1, n_ - 3));
    result_.events.reserve(32);
    pending_.reserve(16);
    health_.gyros.resize(static_cast<std::size_t>(n_));
    result_.attitude.gyro_bias_rad_s.assign(static_cast<std::size_t>(n_), 0.0);
    if (config_.sample_period_s > 0.0) subsets_.prepare(config_.sample_period_s);
    start();
  }

  //! What the pipeline was created from: a pipeline created from it again is this one's initial state.
  const PipelineInputs& inputs() const { return inputs_; }
  const StepResult& step(const Epoch& epoch);
  FdiEvent command_exclude(int id, std::int64_t stamp_ns, bool force);
  FdiEvent command_reinstate(int id, std::int64_t stamp_ns);
  FdiEvent command_reset(std::int64_t stamp_ns);
  std::string describe_thresholds() const;

  const Health& health() const {
    publish_filter_health();
    return health_;
  }
  bool observable(GyroMask gyros) const { return subsets_.geometry().observable(gyros); }
  int gyro_count() const { return n_; }
  const PipelineConfig& config() const { return config_; }
  std::uint64_t arbiter_refusals() const { return arbiter_refusals_; }

  // The pipeline keeps a copy of the configuration that its stages refer to: it is created in place, once.
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

 private:
  bool accept(const Epoch& epoch);
  void reject_outliers();
  //! The gyros left after the jump test have no parity (from the set `before` it): sigma carries what they
  //! may be wrong by over this epoch's step.
  void cover_unchecked_rate(GyroMask before);
  void detect();
  //! The alarm's rows (its detection's, and Hnoise's while the noise model is unchecked) into alarm_rows_;
  //! true when the arbiter lets it decide.
  bool alarm_decides(const Detection& d, const Subset& s);
  void level_changed(const Detection& d);
  void seek_evidence();
  void isolate_filter_bias(const ReferenceFinding& bias);
  void decide_episode();
  void publish_attitude();
  //! The reference sample of this epoch, judged usable, into the attitude (and the pull, the budget, the
  //! anchor).
  void use_reference_sample();
  //! [rad] per axis: the published protection level for the published `sigma_rad`.
  Eigen::Vector3d protection_level(bool observable, const Eigen::Vector3d& sigma_rad);
  //! [rad] Href's share where a drift was matched: what the matches left of the reference's possible bias
  //! and what it has pulled the attitude by since the last (0: no match).
  double ambiguous_reference_rad() const;
  void publish_filter();
  void publish_filter_health() const;
  void update_fdi_available();
  void judge_reference();
  //! The arbiter's decision on the sample tested (`drift_threshold` the drift match's level, +∞ not now);
  //! its rows in reference_rows_ unless every test passed.
  ReferenceDecision decide_reference(const ReferenceEvidence& evidence, double drift_threshold,
                                     GyroMask active);
  //! The rows of a sample some test failed (or whose mean reached the drift match's level): H0 rejected,
  //! Href consistent, Hdrift and each active gyro's hypothesis as the gyros' parity and the test show.
  //! Hdrift's rows for a failed step test: the step against the best ramp (drift_shape), the ramp's wander.
  void add_drift_shape_rows(const RampFit& ramp, GyroMask active, EvidenceRows& rows) const;
  void write_reference_rows(const ReferenceEvidence& evidence, double drift_threshold, GyroMask active,
                            EvidenceRows& rows) const;
  //! The sample's decision applied: the events, sigma, the reference's σ and the matches.
  void apply_reference_verdict(const ReferenceVerdict& v, const Eigen::Vector3d& z, const Eigen::Matrix3d& S,
                               GyroMask active);
  //! A gyro fault just detected, since before a rejection: the parity's rows of that rejection make no call
  //! then, and the arbiter judges it again (the reference used again when it no longer stands alone).
  void reconsider_reference_rejection();
  //! A reference sample set the attitude reference_window_s ago or less.
  bool attitude_set_within_block() const {
    return reference_set_ns_ &&
           frame_.now_ns - *reference_set_ns_ <= seconds_to_ns(config_.reference_window_s);
  }
  //! A calibration mismatch just named: a standing rejection's rows gain Hcal and are judged again.
  void reconsider_rejection_for_calibration();
  //! The arbiter's ruling on a standing rejection's `rows` again: unless it still rejects, the reference is
  //! judged afresh and used (a `reference_accepted` event with `detail` and the rows).
  void judge_rejection_again(const EvidenceRows& rows, const char* detail);
  void match_three_gyro_noise(const Eigen::Vector3d& z, const Eigen::Matrix3d& S);
  void match_common_drift(const Eigen::Vector3d& z, const Eigen::Matrix3d& S);
  //! A noise_model event: `rows` the arbiter's decision's (null: the long window's match, its three rows).
  void learn_pull();
  void emit_drift_matched(double statistic, double threshold, const char* evidence,
                          const EvidenceRows* rows = nullptr);
  //! The bias statistic above which the reference's mean is matched as a common drift (+∞: not now).
  double drift_threshold(GyroMask active);
  void match_drift_mean(const ReferenceVerdict& v, GyroMask active);
  void match_own_noise();
  void check_noise_model();
  void check_long_run_noise();
  //! [-] the white noise variance the parity's spread shows over the model's (≤ 1).
  double shown_white_ratio() const;
  //! [epochs] a block of the long-run spread, and the censoring of its values for subset `s`.
  int long_run_block_epochs() const;
  double long_run_cap(const Subset& s) const;
  void widen_noise(const SpreadFinding& f, const char* evidence);
  void emit_noise_widened(const SpreadFinding& f, const char* evidence);
  void emit_episode_explained(const SpreadFinding& f);
  //! A noise_model event whose one row is `source` rejecting H0 ("the model as stated") at `statistic`.
  FdiEvent model_rejected(EvidenceSource source, double statistic, double threshold) const;
  //! The parity block match has begun: the noise_model event (its row parity_block_match).
  void emit_block_matched(const BlockFinding& f);
  //! The rate solution of the gyros in use when they are exactly three (no parity left), else null.
  const Subset* three_gyros_without_parity();

  //! The motion fit named a mismatch: the `calibration_mismatch` event, with its block's rows.
  void emit_calibration_mismatch();
  void isolate(const Isolation& iso);
  //! decision_rows_: the finding's rows, the open episode's detection, and the calibration fit's Hcal rows.
  void write_decision_rows(const Isolation& iso, bool episode);
  //! The fault's effect on the rate from its onset (or the signature's span) until now, into sigma.
  void cover_fault_span(int gyro, bool episode, std::int64_t now_ns);
  //! The gyro excluded: the filter, the matches and the tests restarted without it; reconfigured or lost.
  void reconfigure_without(int gyro, FaultKind kind, std::int64_t now_ns);
  void isolate_all(Isolations& found);
  void restart_detectors();
  void gap();
  //! The `reference_accepted` event's text: with the re-estimated noise when it is not the configured one.
  std::string reaccepted_detail() const;
  //! [ns] how long before a finding outside an episode its fault may have begun.
  std::int64_t signature_span_ns() const;
  void update_mode(std::int64_t now_ns);
  void emit(FdiEvent event) { result_.events.push_back(std::move(event)); }
  //! An event of `type` at this epoch about the active gyros (the rest for the caller to fill).
  FdiEvent event_now(EventType type) const {
    FdiEvent e;
    e.stamp_ns = frame_.now_ns;
    e.type = type;
    e.gyros = gyro_set_.active();
    return e;
  }
  //! A `detected` event with the rows that rejected H0 (none: the event carries no ledger).
  void emit_detected(DetectionTest test, double statistic, std::int64_t now_ns,
                     const EvidenceRows* rows = nullptr);
  //! The arbiter's ruling on an isolation's rows (the episode's detection rows with them), and the rows an
  //! event carries: every hypothesis of the gyros in use, H0 and Href.
  int rule(const EvidenceRows& rows, std::vector<LedgerRow>& ledger) const;
  FdiEvent acknowledge(CommandVerb verb, int id, CommandOutcome outcome, bool changed, std::int64_t stamp_ns);
  void reinstate(int id);

  //! The initial state beyond what the stages' constructors set: the attitude, the detectors' first epoch.
  void start();

  PipelineConfig config_;
  int n_;
  SubsetCache subsets_;
  BiasHypothesis bias_check_;   //!< the fault-model check of the filter's bias states
  OwnNoiseLevel own_noise_;     //!< three gyros: each gyro's noise level where motion does not reach
  ParitySpread sample_spread_;  //!< the parity's differences between epochs: one sample's noise
  ParitySpread white_spread_;   //!< between consecutive block sums: the white noise every sum sees
  BlockDifferences blocks_;     //!< the block sums of the parity for white_spread_
  bool parity_ran_ = false;     //!< this epoch's parity went through the CUSUM (the full active set)
  GyroSeries series_;
  OutlierGate gate_;
  ParityDetector detector_;
  Isolator isolator_;
  ReferenceMonitor reference_;
  GyroSet gyro_set_;
  RateAttitude attitude_;
  ReferenceConsistency consistency_;  //!< the reference as a sensor that can fail
  DisagreementTrend trend_;  //!< rejected by a slow test: the gyro attitude's error if the gyros are wrong
  ReferenceNoiseMatch noise_match_;  //!< three gyros: a gyro's noise or ramp in the reference's innovations
  ParityBiasMatch bias_match_;       //!< a slow error below the detectors: the gyro's bias model opened
  ReferenceBiasMatch
      drift_match_;             //!< a common drift in the reference's innovations: every bias model opened
  ProtectionLevel protection_;  //!< the integrity bound beside sigma
  CalibrationFit
      calibration_fit_;  //!< the parity against the body rate: a calibration that is not the unit's
  std::vector<OwnNoiseFinding> own_named_;  //!< the gyros own_noise_ named at this epoch (capacity N)
  Eigen::VectorXd held_parity_;  //!< the parity before the jump test, when it left the rest without one
  ReferenceBudget budget_;       //!< the reference's stated bias and latency, which its samples cannot show
  ReferencePull pull_;           //!< what the reference pulled the attitude by since the bias block began
  InnovationMean innovation_mean_;  //!< what the used samples show of the attitude's error now (Hdrift)
  EvidenceRows episode_rows_;       //!< the rows of the detection that opened the open episode
  EvidenceRows alarm_rows_;         //!< this epoch's alarm's rows
  EvidenceRows decision_rows_;      //!< scratch: an isolation's rows with the episode's
  //! scratch: the episode's isolation when decided (its rows' 2 kB not cleared at every epoch)
  Isolation decided_;
  std::uint64_t arbiter_refusals_ = 0;  //!< findings whose rows the arbiter did not confirm
  ReferenceHorizon horizon_;  //!< a late reference fused at its own time (docs/fdi.md, "Late references")

  EpochFrame frame_;
  Isolations found_;
  StepResult result_;
  std::vector<FdiEvent> pending_;  //!< what operator commands caused, emitted with the next step
  //! Mutable for the filter's per-gyro fields, filled when read (publish_filter_health).
  mutable Health health_;
  //! The filter's per-gyro bias and its σ are due in health_: the filter moved since they were filled. Every
  //! change of the filter outside a step fills them first, so they are always those of the last step's end.
  mutable bool filter_health_due_ = false;
  Mode persistent_mode_ = Mode::kNominal;
  GyroMask measured_ = 0;  //!< the gyros of this epoch's rate estimate so far
  StampJudge clock_;       //!< the epoch time check: outliers dropped, forward jumps confirmed
  bool has_time_ = false;
  std::int64_t last_ns_ = 0;
  std::optional<std::int64_t> last_reference_ns_;  //!< the last epoch that carried a usable reference
  bool reference_usable_ = false;  //!< this epoch's reference sample passed the consistency tests
  bool gyros_vouch_ = false;       //!< this epoch: parity among the gyros used, no episode, rate observable
  std::optional<std::int64_t> reference_set_ns_;  //!< the last time a reference sample set the attitude
  //! [ns] when the reference was last rejected, until it is used again, and the rows that rejected it
  std::optional<std::int64_t> reference_rejected_ns_;
  EvidenceRows rejection_rows_;
  EvidenceRows reference_rows_;  //!< the last reference decision's rows
  //! [-] this sample: the λ a match of the reference's mean as a common drift would set, at least ρ times the
  //! last match's (NaN: not judged)
  double drift_ratio_needed_ = std::numeric_limits<double>::quiet_NaN();
  const PipelineInputs inputs_;  //!< what reset() creates the pipeline again from (last: read once a run)
};

}  // namespace tetra::fdi
