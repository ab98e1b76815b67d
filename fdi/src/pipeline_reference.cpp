// The attitude reference judged before anything uses it, and the three-gyro matches it witnesses
// (docs/fdi.md, "Reference consistency", "Three gyros"): part of Pipeline::Impl (pipeline_impl.hpp).

#include "pipeline_impl.hpp"

namespace tetra::fdi {

std::string Pipeline::Impl::reaccepted_detail() const {
  const double sigma_arcsec = consistency_.sigma_rad() / kArcsecToRad;
  if (sigma_arcsec <= config_.reference_sigma_arcsec) return "attitude reference consistent again: used";
  char text[160];
  std::snprintf(text, sizeof text,
                "attitude reference consistent again with its noise re-estimated: used with 1-sigma %.3g "
                "arcsec (%.3g configured)",
                sigma_arcsec, config_.reference_sigma_arcsec);
  return text;
}

void Pipeline::Impl::reconsider_reference_rejection() {
  // A reference rejected by a slow test (nis, bias) had every gyro's hypothesis rejected by the parity, which
  // vouched for them; but a gyro fault grows for a while below the parity's threshold, and its error in the
  // attitude can fail those tests first. A fault detected now whose estimated onset precedes the rejection
  // (less one block of the tests, which it may have filled) shows the parity's rows of that rejection were
  // premature: they make no call, and the arbiter judges the rejection again. With a gyro's hypothesis
  // standing beside Href, the reference is used again, unjudged while the episode is open, and its windows
  // can isolate the gyro (docs/fdi.md). (A jump's or a lag's rows reject the gyros by the test itself.)
  if (!reference_rejected_ns_ || consistency_.state() != ReferenceState::kRejected) return;
  const std::int64_t block_ns = seconds_to_ns(config_.reference_window_s);
  if (*reference_rejected_ns_ < pipeline_time_before_ns(isolator_.episode().onset_ns, block_ns)) return;
  EvidenceRows rows;
  for (LedgerRow row : rejection_rows_) {
    if (row.source == EvidenceSource::kCusum) row.verdict = RowVerdict::kNoCall;
    rows.add(row);
  }
  judge_rejection_again(rows,
                        "attitude reference used again: a gyro fault detected since may have caused its "
                        "rejection");
}

void Pipeline::Impl::reconsider_rejection_for_calibration() {
  // The calibration was just found not to describe the unit: the gyros' attitude, not the reference, may be
  // what disagreed. A standing rejection's rows gain Hcal (consistent), and the arbiter judges it again.
  if (!reference_rejected_ns_ || consistency_.state() != ReferenceState::kRejected) return;
  EvidenceRows rows = rejection_rows_;
  calibration_fit_.add_hcal_rows(EvidenceSource::kReferenceTest, nullptr, rows);
  judge_rejection_again(rows,
                        "attitude reference used again: the calibration does not describe the unit, so "
                        "the gyros' attitude it disagreed with may be the wrong one");
}

void Pipeline::Impl::judge_rejection_again(const EvidenceRows& rows, const char* detail) {
  if (arbitrate_reference(rows.begin(), rows.end(), gyro_set_.active()) == ReferenceDecision::kReject) return;
  consistency_.reopen();
  trend_.stop();
  reference_rejected_ns_.reset();
  FdiEvent e;
  e.stamp_ns = frame_.now_ns;
  e.type = EventType::kReferenceAccepted;
  e.detail = detail;
  e.ledger.assign(rows.begin(), rows.end());
  emit(std::move(e));
}

namespace {
//! The sample's evidence is a mean, which a common drift may explain: no test failed, the bias test did, or
//! the step test did with the long mean beyond the drift match's level (a step fitted to a mean).
bool shows_a_mean(const ReferenceEvidence& evidence, double drift_threshold) {
  return !evidence.failed || *evidence.failed == ReferenceCheck::kBias ||
         (*evidence.failed == ReferenceCheck::kStep && evidence.bias_statistic > drift_threshold);
}
//! The step test failed, and not as a mean: its fit beside the best ramp's (a common drift's shape).
const RampFit* step_against_ramp(const ReferenceEvidence& evidence, bool mean) {
  return !mean && evidence.failed == ReferenceCheck::kStep && evidence.ramp ? &*evidence.ramp : nullptr;
}
}  // namespace

ReferenceDecision Pipeline::Impl::decide_reference(const ReferenceEvidence& evidence, double drift_threshold,
                                                   GyroMask active) {
  const bool mean = shows_a_mean(evidence, drift_threshold);
  if (!evidence.failed && !(mean && evidence.bias_statistic > drift_threshold))
    return ReferenceDecision::kUse;  // every test passed: H0 stands (no rows)
  reference_rows_.clear();
  write_reference_rows(evidence, drift_threshold, active, reference_rows_);
  return arbitrate_reference(reference_rows_.begin(), reference_rows_.end(), active);
}

void Pipeline::Impl::write_reference_rows(const ReferenceEvidence& evidence, double drift_threshold,
                                          GyroMask active, EvidenceRows& rows) const {
  const auto src = EvidenceSource::kReferenceTest;
  const auto& c = consistency_.failed_check();  // the failing test's, or (none failed) the bias test's
  const bool mean = shows_a_mean(evidence, drift_threshold);
  const RampFit* ramp = step_against_ramp(evidence, mean);
  const bool drift_shaped = ramp != nullptr && ramp->step_chi2 <= ramp->ramp_chi2;
  const bool slow = mean || drift_shaped || *evidence.failed == ReferenceCheck::kNis;
  // H0: the failing test rejects it, or the bias test's mean at the drift match's level.
  if (evidence.failed)
    rows.add(judge(src, kHypothesisNone, c.statistic, c.threshold, c.threshold, c.dof));
  else
    rows.add(judge(src, kHypothesisNone, evidence.bias_statistic, drift_threshold, drift_threshold, 3));
  // Href: a wrong reference explains whatever failed.
  rows.add(stated(src, kHypothesisReference, RowVerdict::kConsistent, c.statistic, c.threshold, c.dof));
  // Hdrift: a drift common to the gyros explains a mean alone (no jump, lag or raised NIS before it), while
  // the gyros vouch and a working unit's drift could be that large.
  if (!gyros_vouch_)
    rows.add(stated(src, kHypothesisDrift, RowVerdict::kNoCall, c.statistic, c.threshold, c.dof));
  else if (ramp != nullptr)
    add_drift_shape_rows(*ramp, active, rows);
  else if (!mean)
    rows.add(stated(src, kHypothesisDrift, RowVerdict::kRejected, c.statistic, c.threshold, c.dof));
  else
    rows.add(
        stated(EvidenceSource::kDriftWander, kHypothesisDrift,
               evidence.bias_statistic > drift_threshold ? RowVerdict::kConsistent : RowVerdict::kRejected,
               drift_ratio_needed_, design::reference_max_wander_ratio));
  // Each gyro's: no call unless the gyros vouch; then rejected by the parity for a slow test's evidence (a
  // gyro's fault that moved the attitude so far would have shown in it) and by the test itself for a jump or
  // a lag (a gyro's fault below the parity's threshold is neither).
  for (int id = 1; id <= n_; ++id) {
    if (!has_gyro(active, id)) continue;
    const auto h = static_cast<std::uint8_t>(id);
    if (!gyros_vouch_)
      rows.add(stated(src, h, RowVerdict::kNoCall, c.statistic, c.threshold, c.dof));
    else if (slow)
      rows.add(
          stated(EvidenceSource::kCusum, h, RowVerdict::kRejected, health_.cusum, health_.cusum_threshold));
    else
      rows.add(stated(src, h, RowVerdict::kRejected, c.statistic, c.threshold, c.dof));
  }
  // Hcal: while a calibration mismatch stands, the gyros' own error explains whatever failed.
  calibration_fit_.add_hcal_rows(src, nullptr, rows);
}

void Pipeline::Impl::add_drift_shape_rows(const RampFit& ramp, GyroMask active, EvidenceRows& rows) const {
  // Hdrift against a step (reference_step.hpp): a common drift makes a ramp, so the step test's failure
  // rejects it only where the best step explains the innovations better than the best ramp (their
  // likelihood ratio e^{(χ²_step − χ²_ramp)/2} above 1); where the ramp does at least as well, its rate b
  // over its span T needs a wander as the mean b·T/2 would (at most a working unit's: drift_wander).
  const double excess = ramp.step_chi2 - ramp.ramp_chi2;
  rows.add(judge(EvidenceSource::kDriftShape, kHypothesisDrift, excess, 0.0, 0.0, 3));
  if (excess > 0.0) return;
  const double needed = drift_match_.next_ratio(
      ReferenceBiasMatch::needed_ratio(0.5 * ramp.span_s * ramp.rate_rad_s,
                                       drift_match_.drift_span_s(ramp.span_s, frame_.now_ns), active,
                                       attitude_.filter()),
      frame_.now_ns);
  rows.add(judge(EvidenceSource::kDriftWander, kHypothesisDrift, needed, design::reference_max_wander_ratio,
                 design::reference_max_wander_ratio));
}

void Pipeline::Impl::judge_reference() {
  // The reference sample is tested before anything uses it (docs/fdi.md, "Reference consistency"); the
  // gyros vouch for their attitude when they leave parity, no episode is open and the rate is observable.
  const GyroMask active = gyro_set_.active();
  gyros_vouch_ = subsets_.ready() && subsets_.get(active).dof >= 1 &&
                 subsets_.get(frame_.usable).observable && !isolator_.episode().active;
  reference_usable_ = frame_.reference_q_RB.has_value();
  if (!reference_usable_) {
    if (last_reference_ns_ && frame_.now_ns - *last_reference_ns_ > seconds_to_ns(config_.reference_window_s))
      consistency_.absent();
    return;
  }
  Eigen::Vector3d z;
  Eigen::Matrix3d S;
  if (!subsets_.ready() ||
      !attitude_.predict_reference(*frame_.reference_q_RB, frame_.dt_s, subsets_.period_s(), z, S))
    return;
  // The tests write the evidence, the arbiter decides, the reference's state follows.
  const double drift_level = drift_threshold(active);
  const ReferenceEvidence evidence = consistency_.test_sample(
      frame_.now_ns, z, S, attitude_.omega_BR_B(),
      subsets_.calibration_rate_bound(subsets_.get(active), active, attitude_.omega_meas_B()), gyros_vouch_);
  const ReferenceDecision decision =
      consistency_.judged() ? decide_reference(evidence, drift_level, active) : ReferenceDecision::kUse;
  const ReferenceVerdict v = consistency_.decide(frame_.now_ns, z, S, evidence, decision, drift_level);
  if (v.drift) match_drift_mean(v, active);
  reference_usable_ = v.use;
  if (v.use) innovation_mean_.add(frame_.now_ns, z, S.diagonal());
  // The σ the sample is used with: the configured one, or the re-estimated noise (an operator's reset judges
  // the reference afresh, from the configured σ).
  attitude_.set_reference_sigma_rad(consistency_.sigma_rad());
  reference_.set_reference_sigma_rad(consistency_.sigma_rad());
  noise_match_.set_reference_sigma_rad(consistency_.sigma_rad());
  apply_reference_verdict(v, z, S, active);
  if (v.use) match_three_gyro_noise(z, S);
  if (v.use) match_common_drift(z, S);
  // The pull is measured over the bias blocks the drift matches judge.
  if (!pull_.started()) pull_.start(frame_.now_ns, attitude_.rate_bias_B_rad_s());
  if (consistency_.bias_start_ns() >= 0 && consistency_.bias_start_ns() != pull_.block_ns())
    pull_.roll(consistency_.bias_start_ns(), attitude_.rate_bias_B_rad_s());
}

void Pipeline::Impl::apply_reference_verdict(const ReferenceVerdict& v, const Eigen::Vector3d& z,
                                             const Eigen::Matrix3d& S, GyroMask active) {
  if (v.rejected) {
    trend_.start(frame_.now_ns);
    reference_rejected_ns_ = frame_.now_ns;
    rejection_rows_ = reference_rows_;
  }
  if (v.reaccepted) reference_rejected_ns_.reset();
  if (v.reaccepted) trend_.stop();
  if (consistency_.state() == ReferenceState::kRejected) trend_.add(frame_.now_ns, z, S.diagonal());
  if (v.rejected || v.reaccepted) {
    FdiEvent e;
    e.stamp_ns = frame_.now_ns;
    e.type = v.rejected ? EventType::kReferenceRejected : EventType::kReferenceAccepted;
    e.why = v.rejected ? *v.rejected : ReferenceCheck::kNone;
    e.statistic = consistency_.windowed_nis();
    e.detail = v.rejected ? "attitude reference inconsistent with the gyros: left out, sigma from the gyros"
                          : reaccepted_detail();
    if (v.rejected) e.ledger.assign(reference_rows_.begin(), reference_rows_.end());
    emit(std::move(e));
  }
  if (v.rejected) {
    attitude_.add_variance(v.contamination_rad2);
    budget_.learn(v.step_rad);  // a step the samples carry from now on, which no test of them can see
    // An attitude the reference itself set a block ago or less rests on its samples alone: the rejecting
    // sample's innovation, on every axis, bounds what they put in.
    if (attitude_set_within_block()) attitude_.add_variance(Eigen::Vector3d::Constant(z.squaredNorm()));
  }
  // A jump is left to the gate (a lone wild sample, or ten in a row set the attitude): only the slower tests
  // carry evidence of a gyro fault.
  const bool three = subsets_.get(active).dof < 1;
  if (v.inconsistent && *v.inconsistent != ReferenceCheck::kJump && (three || calibration_fit_.mismatch()) &&
      !isolator_.episode().active) {
    // Redundancy exhausted, or a calibration that does not describe the unit: the reference or the gyros'
    // attitude is wrong and nothing tells which (the arbiter made no call). The reference stays in use (it is
    // the only check left), the disagreement is reported, and the filter's attitude and bias states open by
    // what the innovation shows, so the reference can pull both back.
    emit_detected(DetectionTest::kReference, consistency_.windowed_nis(), frame_.now_ns);
    result_.events.back().why = *v.inconsistent;
    result_.events.back().detail = std::string("attitude reference and gyros disagree (") +
                                   to_string(*v.inconsistent) + "); " +
                                   (three ? "three gyros" : "the calibration does not describe the unit") +
                                   ": the data cannot tell which, sigma and bias states widened";
    result_.events.back().ledger.assign(reference_rows_.begin(), reference_rows_.end());
    attitude_.add_variance(z.cwiseProduct(z));
    attitude_.fault_opened(z.norm() / config_.reference_window_s);
    if (three) noise_match_.match_all(subsets_.get(active).mask);
  }
}

void Pipeline::Impl::match_three_gyro_noise(const Eigen::Vector3d& z, const Eigen::Matrix3d& S) {
  // Three gyros, no parity: the reference's innovations are the only witness of a gyro's ramp, and of a noise
  // its own level cannot show (docs/fdi.md, "Three gyros: a noise increase or a ramp"); the gyro's noise in
  // the filter follows them from then on.
  const Subset* s = three_gyros_without_parity();
  if (s == nullptr) return;
  const auto found = noise_match_.observe(frame_.now_ns, z, S, s->pinv, s->mask, attitude_.filter());
  if (!found) return;
  emit_detected(DetectionTest::kReference, found->statistic, frame_.now_ns);
  result_.events.back().gyro = found->gyro;
  result_.events.back().why = ReferenceCheck::kNis;
  result_.events.back().detail = "attitude reference innovations along gyro " + std::to_string(found->gyro) +
                                 "'s rate axis exceed the model (noise or ramp); three gyros: its noise in "
                                 "the filter matched to the innovations, sigma widened";
}

double Pipeline::Impl::drift_threshold(GyroMask active) {
  // The bias block's mean so far may be matched as a drift only while the gyros vouch, and when a working
  // unit's drift could be that large: the λ its match would set (the Hdrift row's) at most
  // design::reference_max_wander_ratio.
  drift_ratio_needed_ =
      gyros_vouch_
          ? drift_match_.next_ratio(
                ReferenceBiasMatch::needed_ratio(
                    consistency_.bias_mean_rad(),
                    drift_match_.drift_span_s(consistency_.bias_span_s(frame_.now_ns), frame_.now_ns), active,
                    attitude_.filter()),
                frame_.now_ns)
          : std::numeric_limits<double>::quiet_NaN();
  const bool possible = gyros_vouch_ && drift_ratio_needed_ <= design::reference_max_wander_ratio;
  return possible ? drift_match_.threshold() : std::numeric_limits<double>::infinity();
}

void Pipeline::Impl::match_drift_mean(const ReferenceVerdict& v, GyroMask active) {
  // A mean innovation with the gyros consistent: the reference's bias or the gyros' common drift, which the
  // parity cannot see. The drift is matched first — the gyros' bias model opened by what the test saw — and
  // the reference rejected only if its mean persists (docs/fdi.md, "A common drift below the detectors").
  // (A mean that grew beyond a working unit's drift with this very sample opens nothing and says nothing.)
  drift_match_.restart();
  if (drift_match_.match_mean(frame_.now_ns, v.bias_mean_rad, v.bias_span_s, active, attitude_.filter())) {
    learn_pull();
    emit_drift_matched(consistency_.drift_check().statistic, consistency_.drift_check().threshold,
                       v.from_ramp ? "a ramp in the reference's innovations (the step test's, a rate error's "
                                     "shape)"
                                   : "the reference's mean innovation",
                       &reference_rows_);
  }
}

void Pipeline::Impl::match_common_drift(const Eigen::Vector3d& z, const Eigen::Matrix3d& S) {
  // A drift of every gyro's bias together shows in the reference's innovations, not in the parity
  // (docs/fdi.md, "A common drift below the detectors"): judged while the gyros vouch for their attitude, the
  // bias models opened once the blocks show it.
  if (!gyros_vouch_) {
    drift_match_.restart();
    return;
  }
  if (const auto found = drift_match_.observe(frame_.now_ns, z, S, gyro_set_.active(), attitude_.filter())) {
    learn_pull();
    consistency_.restart_bias_block(frame_.now_ns);
    emit_drift_matched(found->statistic, found->threshold,
                       "the reference's mean innovation over four bias windows");
  }
}

void Pipeline::Impl::learn_pull() {
  // A drift matched: the reference's bias stands beside it, and the attitude may be off by what the
  // reference pulled it by over the blocks the match judged; the pull is measured afresh from here.
  budget_.learn_ambiguity(pull_.blocks_rad());
  pull_.start(frame_.now_ns, attitude_.rate_bias_B_rad_s());
}

void Pipeline::Impl::emit_drift_matched(double statistic, double threshold, const char* evidence,
                                        const EvidenceRows* rows) {
  FdiEvent e;
  e.stamp_ns = frame_.now_ns;
  e.type = EventType::kNoiseModel;
  e.statistic = statistic;
  // Its rows: the arbiter's decision's, or (the long window's match) the model (H0) rejected by the mean at
  // the match's level, Hdrift and Href consistent — the data cannot tell a drift of the gyros from a
  // reference's bias; the match is the step that keeps the reference and decides nothing.
  const auto src = EvidenceSource::kReferenceTest;
  if (rows != nullptr) {
    e.ledger.assign(rows->begin(), rows->end());
  } else {
    e.ledger.push_back(judge(src, kHypothesisNone, statistic, threshold, threshold, 3));
    e.ledger.push_back(stated(src, kHypothesisDrift, RowVerdict::kConsistent, statistic, threshold, 3));
    e.ledger.push_back(stated(src, kHypothesisReference, RowVerdict::kConsistent, statistic, threshold, 3));
  }
  char text[400];
  std::snprintf(
      text, sizeof text,
      "gyro bias drift beyond the noise model, common to the gyros (the parity cannot see it), in %s: "
      "the reference or this drift, the data cannot tell which; reference kept, every gyro's bias "
      "random walk opened to %.3g times the model's wander",
      evidence, drift_match_.ratio());
  e.detail = text;
  emit(std::move(e));
}

const Subset* Pipeline::Impl::three_gyros_without_parity() {
  const Subset& s = subsets_.get(gyro_set_.active());
  return tetra::gyro_count(s.mask) == 3 && s.observable && s.dof < 1 ? &s : nullptr;
}

void Pipeline::Impl::match_own_noise() {
  // Three gyros, no parity: a gyro's own fourth differences show its white noise where the body's motion does
  // not reach (docs/fdi.md, "Three gyros: a gyro's own noise level"). A gyro beyond the limit is named, never
  // excluded (three gyros are the rate), and its noise in the filter follows its level until it is normal.
  const Subset* s = three_gyros_without_parity();
  if (!own_noise_.evaluate(s != nullptr ? s->mask : GyroMask{0}, subsets_.sqrt_period(), own_named_)) return;
  for (int id = 1; id <= n_; ++id) noise_match_.set_own_ratio(id, own_noise_.ratio(id), attitude_.filter());
  for (const OwnNoiseFinding& f : own_named_) {
    emit_detected(DetectionTest::kSignature, f.level, frame_.now_ns);
    FdiEvent& e = result_.events.back();
    e.gyro = f.gyro;
    e.ledger.push_back(stated(EvidenceSource::kNoiseLevel, kHypothesisNone, RowVerdict::kRejected, f.level,
                              config_.noise_high_ratio));
    e.ledger.push_back(stated(EvidenceSource::kNoiseLevel, static_cast<std::uint8_t>(f.gyro),
                              RowVerdict::kConsistent, f.level, config_.noise_high_ratio));
    char text[320];
    std::snprintf(text, sizeof text,
                  "gyro %d's own noise level is %.3g times its model (fourth differences, which smooth body "
                  "motion does not reach); three gyros: named, not excluded; its noise in the filter matched "
                  "(variance x%.3g), sigma widened",
                  f.gyro, f.level, f.ratio);
    e.detail = text;
  }
}

}  // namespace tetra::fdi
