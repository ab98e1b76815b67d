// The fusion pipeline: the stages of docs/fdi.md, in order, over one preallocated frame per epoch.
//
//   input checks ─ GyroSeries::ingest (validate, calibrate, per-gyro series)
//   outliers     ─ OutlierGate (one-epoch jump test)
//   rate, parity ─ RateAttitude::measure, ParityDetector (χ², CUSUM)
//   isolation    ─ GyroSeries::check (signatures), ReferenceMonitor, Isolator (onset, GLT)
//   gyro set     ─ GyroSet (exclusions, latched) → mode
//   attitude     ─ RateAttitude::propagate (trapezoid, filter covariance), RateAttitude::reference (filter
//                  update with the epoch's reference sample)
//
// Each stage owns its state and resets it itself; the pipeline only orders them and turns their findings into
// events. Steady state allocates nothing: every buffer is sized at creation (or when the sample period is
// first known) and events reuse a reserved vector.

#include "pipeline_impl.hpp"

namespace tetra::fdi {

namespace {
//! What three gyros can no longer tell, said where the reconfiguration is (docs/fdi.md).
constexpr const char* kThreeGyrosLeft =
    "three gyros left: no parity; the jump, onset, noise-level and coarse repeated-value tests make no call; "
    "invalid, dropout, stuck, zero, low variance and the reference go on";
}  // namespace

// ---------------------------------------------------------------------------------------------
// one epoch

const StepResult& Pipeline::Impl::step(const Epoch& epoch) {
  result_.events.clear();
  for (auto& e : pending_) result_.events.push_back(std::move(e));
  pending_.clear();
  result_.accepted = accept(epoch);
  if (!result_.accepted) return result_;
  if (frame_.dt_s > config_.max_gap_s) gap();
  series_.ingest(epoch, frame_, health_.counters);
  own_noise_.ingest(frame_, subsets_.ready() ? subsets_.period_s() : 0.0);
  isolator_.record(frame_);
  frame_.usable = frame_.valid & gyro_set_.active();
  measured_ = ~GyroMask{0};
  parity_ran_ = false;
  if (subsets_.ready()) {
    reject_outliers();
    check_noise_model();
    series_.observe_motion(frame_, subsets_);
    detect();
    check_long_run_noise();
    match_own_noise();
  }
  reference_.integrate(frame_, gyro_set_.excluded(), attitude_.omega_meas_B(), attitude_.earth_rate_B(),
                       subsets_.observable(frame_.usable));
  judge_reference();
  seek_evidence();
  update_mode(frame_.now_ns);
  if (frame_.reference_q_RB && reference_usable_) last_reference_ns_ = frame_.now_ns;
  update_fdi_available();
  publish_attitude();
  return result_;
}

void Pipeline::Impl::update_fdi_available() {
  // Fault detection needs parity among the active gyros or an attitude reference heard within its window.
  const GyroMask active = gyro_set_.active();
  const bool parity = subsets_.ready() ? subsets_.get(active).dof >= 1 : tetra::gyro_count(active) >= 4;
  const bool reference =
      last_reference_ns_ && frame_.now_ns - *last_reference_ns_ <= seconds_to_ns(config_.reference_window_s);
  const bool available = parity || reference;
  result_.attitude.fdi_available = available;
  if (available == health_.fdi_available) return;
  health_.fdi_available = available;
  FdiEvent e = event_now(available ? EventType::kFdiAvailable : EventType::kFdiUnavailable);
  e.detail = available
                 ? "fault detection available again"
                 : "no parity left among the gyros used and no attitude reference: a new fault would go "
                   "unseen";
  emit(std::move(e));
}

bool Pipeline::Impl::accept(const Epoch& epoch) {
  auto& counters = health_.counters;
  if (static_cast<int>(epoch.raw.size()) != n_ || static_cast<int>(epoch.present.size()) != n_) {
    ++counters.epochs_rejected_shape;
    return false;
  }
  switch (clock_.judge(epoch.stamp_ns)) {
    case StampVerdict::kAccepted:
      break;
    case StampVerdict::kNotIncreasing:
      ++counters.epochs_rejected_time;  // duplicate, backward or out of order: the attitude is not advanced
      return false;
    case StampVerdict::kOutlier:
      ++counters.epochs_time_outlier;  // far from the stream's time: dropped, the time is not moved
      return false;
  }
  frame_.dt_s = has_time_ ? ns_to_seconds(epoch.stamp_ns - last_ns_) : 0.0;
  if (!has_time_) protection_.anchor(epoch.stamp_ns);  // the start: the attitude known to its initial σ
  if (!subsets_.ready() && frame_.dt_s > 0.0) subsets_.prepare(frame_.dt_s);
  if (!clock_.has_period() && subsets_.ready()) clock_.set_period(seconds_to_ns(subsets_.period_s()));
  if (subsets_.ready()) horizon_.prepare(subsets_.period_s());
  has_time_ = true;
  last_ns_ = epoch.stamp_ns;
  frame_.now_ns = epoch.stamp_ns;
  ++frame_.index;
  ++counters.epochs_accepted;
  frame_.reference_q_RB.reset();
  if (epoch.reference_q_RB) {
    const Quaternion& q = *epoch.reference_q_RB;
    const bool unit = q.coeffs().allFinite() && std::abs(q.norm() - 1.0) <= 1e-3;
    if (unit)
      frame_.reference_q_RB = horizon_.admit(epoch, q.normalized(), attitude_.omega_BR_B(), frame_.dt_s,
                                             counters, result_.events);
    else
      ++counters.reference_invalid;
  }
  return true;
}

void Pipeline::Impl::reject_outliers() {
  const GyroMask before = frame_.usable;
  gate_.update(frame_, subsets_, series_, health_.counters, found_);
  isolate_all(found_);
  frame_.usable &= gyro_set_.active();
  cover_unchecked_rate(before & gyro_set_.active());
}

void Pipeline::Impl::cover_unchecked_rate(GyroMask before) {
  // The jump test left a gyro out of this epoch as the one whose jump explains the parity's: right when its
  // hypothesis is, but with four gyros every hypothesis explains a single parity, and only the motion judged
  // possible picks one. When the gyros left have no parity of their own nothing checks them, so the rate
  // they give carries what any of them may be wrong by (docs/fdi.md, "One-epoch jump test"): the largest
  // rate error under every single-gyro hypothesis of the parity before the test, for this epoch's step.
  if (frame_.usable == before || !(frame_.dt_s > 0.0)) return;
  const Subset& used = subsets_.get(frame_.usable);
  const Subset& full = subsets_.get(before);
  if (used.dof >= 1 || !used.observable || full.dof < 1) return;
  (void)apply_parity(full, before, frame_.y_rad_s.data(), subsets_.sqrt_period(), held_parity_.data());
  attitude_.add_bound(unchecked_rate_bound(full, used, held_parity_, subsets_.sqrt_period()) * frame_.dt_s);
}

bool Pipeline::Impl::alarm_decides(const Detection& d, const Subset& s) {
  alarm_rows_.clear();
  alarm_rows_.detection(source_of(d.test), d.statistic, d.threshold, d.dof);
  // Until the parity's spread has checked the noise model, Hnoise may explain the alarm.
  const auto noise = sample_spread_.noise_row(d.statistic, d.threshold, d.test == DetectionTest::kChi2);
  if (noise) alarm_rows_.add(*noise);
  // A sum's alarm with one degree of freedom, on a unit whose one sample does not show the white noise (the
  // quantization's): Hnoise stands while the white noise the long-run spread estimates explains it. (With
  // d ≥ 2 the spread gathers d values a block and rules within minutes: docs/fdi.md, "A unit noisier".)
  const bool sum = d.test == DetectionTest::kCusum || d.test == DetectionTest::kLevel;
  if (sum && s.dof == 1 && subsets_.quantization_share() > design::spread_white_dominates)
    alarm_rows_.add(white_spread_.allowed_row(d.statistic, d.threshold, long_run_cap(s)));
  return arbitrate_detection(alarm_rows_);
}

void Pipeline::Impl::detect() {
  const Subset& s = subsets_.get(frame_.usable);
  attitude_.measure(s, frame_);
  measured_ = frame_.usable;
  const GyroMask active = gyro_set_.active();
  const double calibration = subsets_.calibration_bound(s, frame_.usable, attitude_.omega_meas_B());
  Detection d = detector_.update(frame_, s, active, subsets_.sqrt_period(), calibration, health_);
  parity_ran_ = d.cusum_ran;
  const bool held = d.alarm && !alarm_decides(d, s);
  if (held) d.alarm = false;
  protection_.widen(calibration, frame_.dt_s);  // the CUSUM's reference k + D: a larger fault unseen
  if (d.cusum_ran) {
    isolator_.accumulate(detector_.parity_measured(), s.dof, attitude_.omega_meas_B());
    bias_check_.record(detector_.parity(), s);
    if (frame_.usable == active &&
        calibration_fit_.record(detector_.parity_measured(), s, active, attitude_.omega_meas_B(),
                                frame_.now_ns, subsets_, config_)) {
      emit_calibration_mismatch();
      reconsider_rejection_for_calibration();
    }
  }
  if (d.cusum_ran && !d.alarm && !held && !isolator_.episode().active) calibration_fit_.judged_nominal();
  // An open episode ends only once the parity is back to nominal for clear_after_s: a fault whose CUSUM
  // alarms grow sparse (a slow ramp near the reference k) keeps it open.
  if (d.cusum_ran && !d.alarm && isolator_.episode().active && !detector_.parity_nominal(s))
    isolator_.alarmed(frame_.now_ns);
  if (!d.alarm) return;
  if (d.test == DetectionTest::kLevel) {
    level_changed(d);
    return;
  }
  if (isolator_.open(d, frame_.now_ns, frame_.index, s, detector_, attitude_.omega_meas_B())) {
    attitude_.hold_biases(isolator_.episode().onset_ns);  // before the filter opens them to the fault
    detector_.open_episode();
    episode_rows_.clear();
    episode_rows_.add(alarm_rows_);
    emit_detected(d.test, d.statistic, frame_.now_ns, &episode_rows_);
    reconsider_reference_rejection();
    // The fault acted since its onset: widen the uncertainty for the time already spent.
    attitude_.add_bound(
        fault_rate_bound(subsets_.get(active), detector_.parity_ema(), subsets_.sqrt_period()) *
        ns_to_seconds(frame_.now_ns - isolator_.episode().onset_ns));
    attitude_.fault_opened(
        fault_size_bound(subsets_.get(active), detector_.parity_ema(), subsets_.sqrt_period()));
  }
  isolator_.alarmed(frame_.now_ns);
  detector_.restart_after_alarm();  // a persisting fault keeps raising alarms, a gone one stops
}

void Pipeline::Impl::level_changed(const Detection& d) {
  // A new fault during the open episode: a new detection, and the uncertainty widened as for the first
  // (docs/fdi.md, "Detection"). The episode's isolation goes on as it was (a second onset inside a drift
  // gave the onset test chances to blame a healthy gyro); the level test measures from the new level.
  const GyroMask active = gyro_set_.active();
  EvidenceRows level;
  level.detection(source_of(d.test), d.statistic, d.threshold, d.dof);
  emit_detected(d.test, d.statistic, frame_.now_ns, &level);
  attitude_.add_bound(fault_rate_bound(subsets_.get(active), detector_.parity_ema(), subsets_.sqrt_period()) *
                      ns_to_seconds(frame_.now_ns - isolator_.onset_time(d.onset_index, frame_.index)));
  attitude_.fault_opened(
      fault_size_bound(subsets_.get(active), detector_.parity_ema(), subsets_.sqrt_period()));
  detector_.open_episode();
  isolator_.alarmed(frame_.now_ns);
  detector_.restart_after_alarm();
}

void Pipeline::Impl::seek_evidence() {
  series_.check(frame_.now_ns, gyro_set_.excluded(), subsets_.period_s(), subsets_.sqrt_period(), found_);
  isolate_all(found_);
  if (frame_.reference_q_RB && reference_usable_ && subsets_.ready()) {
    const auto finding =
        reference_.update(frame_.now_ns, *frame_.reference_q_RB, gyro_set_.excluded(), series_);
    if (finding) {
      Isolation iso{finding->gyro,      FaultKind::kScale, Evidence::kReference, DetectionTest::kReference,
                    finding->statistic, finding->rows};
      if (!finding->scale)
        iso.kind =
            isolator_.classify_drift(finding->gyro, frame_.index, gyro_set_.active(), subsets_, iso.rows);
      isolate(iso);
    } else if (config_.filter_bias_isolation && isolator_.episode().active && attitude_.reference_aided()) {
      // The filter's bias estimates (reference + parity make each gyro's observable): one gyro alone off.
      if (const auto bias = reference_.filter_update(attitude_.filter(), gyro_set_.active()))
        isolate_filter_bias(*bias);
    }
    bias_check_.close_bin(frame_.now_ns);
  }
  if (subsets_.ready()) decide_episode();
}

void Pipeline::Impl::isolate_filter_bias(const ReferenceFinding& bias) {
  // A fault that is not a bias (a spike, a scale error during a slew, a coarsely quantized output) spreads
  // over the bias states and can put a healthy gyro's alone beyond the threshold. So the filter's rows judge
  // only the gyro they flag; one single-gyro fault fitted to the episode's parity and reference records
  // judges every gyro (bias_fit: the others rejected by a margin), and the fault must still be there, of the
  // filter's sign, in the latest half of the span (bias_persists). The arbiter decides (docs/fdi.md).
  const GyroMask active = gyro_set_.active();
  const Subset& s = subsets_.get(active);
  const std::int64_t now = frame_.now_ns;
  const double window_s = config_.reference_window_s;
  const std::int64_t from = std::max(isolator_.episode().onset_ns, now - seconds_to_ns(window_s));
  reference_.filter_rearm(bias.gyro);  // until the rows make the case, it is retried at every sample
  SpanDisagreement span;
  if (!reference_.span(from, design::filter_bias_min_span_fraction * window_s, gyro_set_.excluded(), series_,
                       span))
    return;  // too short a span to judge yet
  Isolation iso{bias.gyro,      FaultKind::kBias, Evidence::kReference, DetectionTest::kReference,
                bias.statistic, bias.rows};
  const BiasFit fit = bias_check_.best(s, span, subsets_.sqrt_period(), iso.rows);
  if (arbitrate(iso.rows.begin(), iso.rows.end(), active, true) != bias.gyro) return;  // not singled out
  SpanDisagreement late;
  const std::int64_t middle = span.start_ns + (now - span.start_ns) / 2;
  if (!reference_.span(middle, design::filter_bias_late_span_fraction * window_s, gyro_set_.excluded(),
                       series_, late))
    return;
  // The arbiter singled out the best fit (fit.gyro is bias.gyro); it must persist with the sign of the fit
  // and of the filter's estimate alike (sign 0, when those differ, persists nowhere).
  const double sign = fit.size_rad_s * attitude_.filter().bias_rad_s(bias.gyro) > 0.0 ? fit.size_rad_s : 0.0;
  const auto persists = bias_check_.persists(bias.gyro, sign, s, late, subsets_.sqrt_period());
  if (!persists) return;
  iso.rows.add(*persists);
  if (arbitrate(iso.rows.begin(), iso.rows.end(), active, true) != bias.gyro) return;
  iso.kind = reference_.span_scale(bias.gyro, span)
                 ? FaultKind::kScale
                 : isolator_.classify_drift(bias.gyro, frame_.index, active, subsets_, iso.rows);
  isolate(iso);
}

void Pipeline::Impl::decide_episode() {
  const Episode& episode = isolator_.episode();
  switch (isolator_.decide(frame_.now_ns, frame_.index, gyro_set_.active(), subsets_, series_, decided_)) {
    case Verdict::kNone:
      break;
    case Verdict::kIsolated:
      isolate(decided_);
      break;
    case Verdict::kUnisolated: {
      FdiEvent u;
      u.stamp_ns = frame_.now_ns;
      u.type = EventType::kUnisolated;
      u.test = episode.test;
      u.statistic = episode.statistic;
      u.detail = "no evidence tells which gyro; all gyros kept, sigma covers every single-gyro hypothesis";
      decision_rows_.clear();
      decision_rows_.add(episode_rows_);
      decision_rows_.add(isolator_.rows());
      (void)rule(decision_rows_, u.ledger);
      emit(std::move(u));
      break;
    }
    case Verdict::kCleared: {
      detector_.close_episode(frame_.index + 1);  // no level test outside an episode
      attitude_.release_biases();
      FdiEvent c = event_now(EventType::kCleared);
      c.detail = "no alarm for clear_after_s";
      c.ledger.push_back(stated(EvidenceSource::kQuiet, kHypothesisNone, RowVerdict::kConsistent,
                                ns_to_seconds(frame_.now_ns - episode.last_alarm_ns), config_.clear_after_s));
      emit(std::move(c));
      break;
    }
  }
}

void Pipeline::Impl::publish_attitude() {
  frame_.usable = gate_.usable(frame_, gyro_set_.active());
  bool observable = false;
  if (!subsets_.ready()) {
    // First epoch: no time step yet, so no sample period and no subset cache; the rate is still estimated (it
    // is published, not integrated).
    observable = attitude_.measure_unprepared(subsets_.geometry(), frame_);
  } else {
    const Subset& sol = subsets_.get(frame_.usable);
    observable = sol.observable;
    // A gyro isolated during this epoch leaves the published set: the rate is the one of the gyros published.
    if (frame_.usable != measured_) attitude_.measure(sol, frame_);
    if (frame_.dt_s > 0.0) {
      // The active set's subset only when needed: for the bound of an open episode, or the noise of a lost
      // rate.
      const bool episode = isolator_.episode().active;
      const Subset* active = episode || !sol.observable ? &subsets_.get(gyro_set_.active()) : nullptr;
      // ...and the rate error the calibration's stated σ allows at this rate.
      const Eigen::Vector3d bound =
          (episode ? fault_rate_bound(*active, detector_.parity_ema(), subsets_.sqrt_period())
                   : Eigen::Vector3d::Zero()) +
          subsets_.calibration_rate_bound(sol, frame_.usable, attitude_.omega_meas_B());
      attitude_.propagate(frame_, sol, active, bound, subsets_.period_s());
      // The epoch's parity, when it was computed over the gyros published, measures their biases; over the
      // whole active set outside an episode, once the reference has been seen (the filter then estimates the
      // biases, so the blocks of its innovations are nearly independent), its blocks also judge each gyro's
      // bias model (a slow error below the detectors).
      if (frame_.usable == measured_ && sol.observable) {
        if (episode)
          bias_match_.restart();
        else if (frame_.usable == gyro_set_.active() && attitude_.reference_aided()) {
          if (const auto found = bias_match_.observe(frame_.now_ns, sol, detector_.parity(),
                                                     subsets_.sqrt_period(), attitude_.filter()))
            emit_block_matched(*found);
        }
        attitude_.parity(sol, detector_.parity(), subsets_.sqrt_period());
      }
    }
  }
  const Quaternion q_propagated_RB = attitude_.q_RB();  // the gyros' step, for the fusion horizon
  use_reference_sample();
  publish_filter();
  auto& a = result_.attitude;
  a.omega_BR_B_rad_s = attitude_.omega_BR_B();
  a.stamp_ns = frame_.now_ns;
  a.q_RB = attitude_.q_RB();
  a.sigma_rad = attitude_.sigma_rad();
  // What the used reference samples show of the error beyond the filter's own sigma (a drift below the
  // detectors, before its match; innovation_mean.hpp), on every axis: the samples' frame turns with the body.
  if (const double shown_rad = innovation_mean_.excess_rad(a.sigma_rad); shown_rad > 0.0)
    a.sigma_rad = root_sum_square(a.sigma_rad, Eigen::Vector3d::Constant(shown_rad));
  if (trend_.active()) a.sigma_rad = root_sum_square(a.sigma_rad, trend_.bound(frame_.now_ns));
  if (budget_.active()) a.sigma_rad = root_sum_square(a.sigma_rad, budget_.sigma_rad());
  a.protection_level_rad = protection_level(observable, a.sigma_rad);  // its Href term below as a bound
  // Href where a drift was matched: the reference's own bias the data could not tell from the gyros' drift
  // (what the matches left and what the reference has pulled the attitude by since). Sigma covers every
  // hypothesis the data leave consistent (the rule), on every axis: the pull's direction turns with the body.
  if (const double href_rad = ambiguous_reference_rad(); href_rad > 0.0)
    a.sigma_rad = root_sum_square(a.sigma_rad, Eigen::Vector3d::Constant(href_rad));
  health_.protection_level_rad = a.protection_level_rad;
  a.mode = observable ? persistent_mode_ : Mode::kLost;
  a.gyros = observable ? frame_.usable : GyroMask{0};
  health_.used = a.gyros;
  attitude_.finish_epoch();
  horizon_.record(frame_.now_ns, q_propagated_RB, attitude_.q_RB());
}

void Pipeline::Impl::use_reference_sample() {
  // The reference sample, at this epoch's time, once the attitude is there too.
  if (frame_.reference_q_RB && !reference_usable_) ++health_.counters.reference_rejected;
  if (frame_.reference_q_RB && reference_usable_) {
    // Never set the attitude onto a reference that disagrees with gyros that vouch for theirs.
    const Quaternion q_before_RB = attitude_.q_RB();
    const ReferenceUse use = attitude_.reference(*frame_.reference_q_RB, !gyros_vouch_);
    if (use == ReferenceUse::kAccepted)
      pull_.add(frame_.now_ns, q_before_RB, attitude_.reference_correction_rad(),
                attitude_.rate_bias_B_rad_s());
    if (use != ReferenceUse::kRejected) {
      protection_.anchor(frame_.now_ns);  // the error known again
      budget_.used(ns_to_seconds(frame_.now_ns), attitude_.omega_BR_B());
    }
    if (use == ReferenceUse::kInitialized || use == ReferenceUse::kReinitialized) {
      reference_set_ns_ = frame_.now_ns;
      innovation_mean_.reset();  // the attitude set onto the reference: its error is new
    }
    ++(use == ReferenceUse::kRejected ? health_.counters.reference_rejected
                                      : health_.counters.reference_accepted);
    if (use == ReferenceUse::kReinitialized) ++health_.counters.reference_reinitialized;
    if (!isolator_.episode().active) attitude_.snapshot_biases(frame_.now_ns);
  }
}

double Pipeline::Impl::ambiguous_reference_rad() const {
  const double ambiguous_rad = budget_.ambiguous_rad();
  return ambiguous_rad > 0.0 ? ambiguous_rad + pull_.since_rad() : 0.0;
}

Eigen::Vector3d Pipeline::Impl::protection_level(bool observable, const Eigen::Vector3d& sigma_rad) {
  if (!observable) return Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d pl = subsets_.ready() ? protection_.bound(subsets_.get(gyro_set_.active()), sigma_rad,
                                                            frame_.now_ns, subsets_.sqrt_period())
                                        : Eigen::Vector3d(protection_.k_md() * sigma_rad);
  // Href where a drift was matched: the reference's bias the data could not tell from the drift (what the
  // matches left, and what the reference has pulled the attitude by since the last one); and while the bias
  // block's mean stands beyond a good reference's, undecided, what a match would learn now.
  const double ambiguous_rad = budget_.ambiguous_rad();
  double href_rad = ambiguous_reference_rad();
  if (consistency_.mean_unresolved()) href_rad = std::max(href_rad, ambiguous_rad + pull_.blocks_rad());
  if (href_rad > 0.0) pl = pl.cwiseMax(protection_.k_md() * sigma_rad + Eigen::Vector3d::Constant(href_rad));
  // Hdrift before any match: the error the used samples show now, beside the filter's σ and the mean's noise.
  if (!innovation_mean_.empty()) {
    const Eigen::Vector3d spread = (sigma_rad.cwiseAbs2() + innovation_mean_.variance_rad2()).cwiseSqrt();
    const double shown_rad = innovation_mean_.mean_rad().norm();
    pl = pl.cwiseMax(protection_.k_md() * spread + Eigen::Vector3d::Constant(shown_rad));
  }
  return pl;
}

void Pipeline::Impl::publish_filter() {
  const Mekf& f = attitude_.filter();
  auto& a = result_.attitude;
  for (int id = 1; id <= n_; ++id) a.gyro_bias_rad_s[static_cast<std::size_t>(id - 1)] = f.bias_rad_s(id);
  health_.reference_chi2 = attitude_.reference_chi2();
  health_.reference_state = consistency_.state();
  health_.reference_nis = consistency_.windowed_nis();
  filter_health_due_ = true;  // read far less often than a step runs
}

void Pipeline::Impl::publish_filter_health() const {
  if (!filter_health_due_) return;
  filter_health_due_ = false;
  const Mekf& f = attitude_.filter();
  for (int id = 1; id <= n_; ++id) {
    auto& h = health_.gyros[static_cast<std::size_t>(id - 1)];
    h.bias_rad_s = f.bias_rad_s(id);
    h.bias_sigma_rad_s = f.bias_sigma_rad_s(id);
  }
}

// ---------------------------------------------------------------------------------------------
// isolation, reconfiguration, modes

void Pipeline::Impl::isolate_all(Isolations& found) {
  for (const auto& iso : found) isolate(iso);
  found.clear();
}

void Pipeline::Impl::isolate(const Isolation& iso) {
  if (gyro_set_.is_excluded(iso.gyro)) return;
  const std::int64_t now = frame_.now_ns;
  const bool episode = isolator_.episode().active;
  // The arbiter decides: a finding whose rows do not make the case (another hypothesis standing, one not
  // judged, no fault shown) excludes nothing (docs/fdi.md, "The ledger and the arbiter").
  write_decision_rows(iso, episode);
  FdiEvent e;
  if (rule(decision_rows_, e.ledger) != iso.gyro) {
    ++arbiter_refusals_;
    return;
  }
  if (!episode) emit_detected(iso.test, iso.statistic, now, &decision_rows_);
  cover_fault_span(iso.gyro, episode, now);
  e.stamp_ns = now;
  e.type = EventType::kIsolated;
  e.gyro = iso.gyro;
  e.kind = iso.kind;
  e.evidence = iso.evidence;
  e.test = iso.test;
  e.statistic = iso.statistic;
  if (!config_.exclusion_enabled) {
    // An experiment that measures what exclusion is worth: the finding is reported, the gyro stays in the
    // solution, and detection starts again (a fault that persists is found again).
    e.detail = "exclusion_enabled is false: gyro kept";
    emit(std::move(e));
    restart_detectors();
    update_mode(now);
    return;
  }
  emit(std::move(e));
  reconfigure_without(iso.gyro, iso.kind, now);
}

void Pipeline::Impl::write_decision_rows(const Isolation& iso, bool episode) {
  decision_rows_.clear();
  decision_rows_.add(iso.rows);
  if (episode) decision_rows_.add(episode_rows_);
  calibration_fit_.add_hcal_rows(source_of(iso.evidence), episode ? &episode_rows_ : nullptr, decision_rows_);
}

void Pipeline::Impl::cover_fault_span(int gyro, bool episode, std::int64_t now_ns) {
  if (!subsets_.ready()) return;
  // The fault corrupted the rate from its onset until now: keep that in the attitude uncertainty — the
  // parity's mean fault over the span, and the sum of each kept epoch's (a fault that grew faster than the
  // mean followed).
  const GyroMask active = gyro_set_.active();
  const std::int64_t span_epochs =
      static_cast<std::int64_t>(std::ceil(ns_to_seconds(signature_span_ns()) / subsets_.period_s()));
  const std::int64_t from = episode ? isolator_.episode().onset_index : frame_.index - span_epochs;
  Eigen::Vector3d bound = isolator_.fault_angle(gyro, from, frame_.index, active, subsets_);
  if (episode)
    bound = bound.cwiseMax(fault_angle_error(subsets_.get(active), gyro, detector_.parity_ema(),
                                             subsets_.sqrt_period(),
                                             ns_to_seconds(now_ns - isolator_.episode().onset_ns)));
  attitude_.add_bound(bound);
}

void Pipeline::Impl::reconfigure_without(int gyro, FaultKind kind, std::int64_t now_ns) {
  gyro_set_.exclude(gyro, kind);
  // A set left without parity has nothing to fit: no mismatch stands for it (one with parity is judged anew).
  if (subsets_.get(gyro_set_.active()).dof < 1) calibration_fit_.reset();
  attitude_.freeze(gyro);
  bias_match_.release(attitude_.filter());  // the error that opened the bias models may have been this fault
  drift_match_.reset();                     // (and the drift matched may have been it)
  // What the fault leaked into the other gyros' bias states since its onset is undone (docs/fdi.md).
  attitude_.repair_biases(gyro_set_.active(),
                          isolator_.episode().active ? isolator_.episode().onset_ns
                                                     : pipeline_time_before_ns(now_ns, signature_span_ns()),
                          now_ns);
  restart_detectors();
  // The remaining gyros' tests restart from evidence the removed fault did not touch (docs/fdi.md, "One
  // fault, one exclusion").
  series_.restart_evidence();
  reference_.restart_windows();
  FdiEvent rc;
  rc.stamp_ns = now_ns;
  rc.gyros = gyro_set_.active();
  rc.type = subsets_.observable(rc.gyros) ? EventType::kReconfigured : EventType::kLost;
  if (rc.type == EventType::kReconfigured && tetra::gyro_count(rc.gyros) == 3) rc.detail = kThreeGyrosLeft;
  emit(std::move(rc));
  update_mode(now_ns);
}

void Pipeline::Impl::restart_detectors() {
  detector_.restart(frame_.index + 1);
  isolator_.close();
  gate_.restart();
  attitude_.release_biases();
  consistency_.restart();
}

std::int64_t Pipeline::Impl::signature_span_ns() const {
  // The longest a finding without an episode takes from its fault's onset: a timeout, the repeated values,
  // the jump test's confirmation; one sample period more for the onset's own epoch.
  const double period = subsets_.ready() ? subsets_.period_s() : 0.0;
  const double span_s = std::max({config_.dropout_timeout_s, design::stuck_repeat_count * period,
                                  design::onset_confirm_epochs * period}) +
                        period;
  // A span longer than any run (epochs days apart) means "since the start"; bounded so that its nanoseconds
  // and now − span stay within int64 (fuzz_pipeline found 2.5e10 s).
  constexpr double kMaxSpan_s = 1.0e8;
  return seconds_to_ns(span_s < kMaxSpan_s ? span_s : kMaxSpan_s);
}

void Pipeline::Impl::gap() {
  // No epoch for dt: a fact of the data path, not of a gyro (docs/fdi.md, "Data path"). The rate between the
  // two epochs is unknown but for the acceleration bound: the trapezoid over the gap can miss the angle by up
  // to a·τ²/4 per axis, a the bound or the acceleration seen before it (RateAttitude::gap_bound_rad). The
  // tests whose evidence would straddle the gap start again on its far side.
  const double tau = frame_.dt_s;
  const double hidden = attitude_.gap_bound_rad(tau, subsets_.get(gyro_set_.active()));
  attitude_.add_bound(Eigen::Vector3d::Constant(hidden));
  series_.bridge_gap();
  own_noise_.bridge_gap();
  bias_match_.restart();  // a block does not straddle the gap
  drift_match_.restart();
  gate_.restart();
  reference_.restart_windows();
  FdiEvent e;
  e.stamp_ns = frame_.now_ns;
  e.type = EventType::kGap;
  e.statistic = tau;
  char text[192];
  std::snprintf(text, sizeof text,
                "no epoch for %.6g s: attitude propagated across it, sigma widened by %.3g deg per axis "
                "(max_angular_acceleration_dps2, or the acceleration seen before it if larger, * gap^2 / 4)",
                tau, hidden * kRadToDeg);
  e.detail = text;
  emit(std::move(e));
}

void Pipeline::Impl::emit_calibration_mismatch() {
  FdiEvent e;
  e.stamp_ns = frame_.now_ns;
  e.type = EventType::kCalibrationMismatch;
  e.statistic = calibration_fit_.statistic();
  e.detail =
      "the parity follows the body rate as no single gyro's fault makes it: the calibration's scale factors "
      "or axes do not describe this unit; nothing is excluded on the parity while it stands, and sigma "
      "does not cover it: calibrate the unit (tetra calibrate)";
  e.ledger.assign(calibration_fit_.rows().begin(), calibration_fit_.rows().end());
  emit(std::move(e));
}

void Pipeline::Impl::emit_detected(DetectionTest test, double statistic, std::int64_t now_ns,
                                   const EvidenceRows* rows) {
  FdiEvent d;
  d.stamp_ns = now_ns;
  d.type = EventType::kDetected;
  d.test = test;
  d.statistic = statistic;
  if (rows != nullptr) {
    for (const LedgerRow& row : *rows) {
      if (row.hypothesis == kHypothesisNone || row.hypothesis == kHypothesisReference ||
          row.hypothesis == kHypothesisNoise)
        d.ledger.push_back(row);
    }
  }
  emit(std::move(d));
}

int Pipeline::Impl::rule(const EvidenceRows& rows, std::vector<LedgerRow>& ledger) const {
  const GyroMask active = gyro_set_.active();
  const bool reference =
      last_reference_ns_ && frame_.now_ns - *last_reference_ns_ <= seconds_to_ns(config_.reference_window_s);
  ledger.clear();
  for (const LedgerRow& row : rows) {
    const bool gyro = row.hypothesis != kHypothesisNone && row.hypothesis <= kMaxGyros;
    if (!gyro || has_gyro(active, row.hypothesis)) ledger.push_back(row);
  }
  return arbitrate(rows, active, reference);
}

void Pipeline::Impl::update_mode(std::int64_t now_ns) {
  const GyroMask active = gyro_set_.active();
  Mode mode = Mode::kNominal;
  if (!subsets_.observable(active)) {
    mode = Mode::kLost;
  } else if (isolator_.episode().active) {
    mode = Mode::kSuspect;
  } else if (active != gyro_set_.all()) {
    mode = Mode::kDegraded;
  }
  persistent_mode_ = mode;
  health_.stamp_ns = now_ns;
  health_.mode = mode;
  for (int id = 1; id <= n_; ++id) {
    auto& h = health_.gyros[static_cast<std::size_t>(id - 1)];
    h.kind = gyro_set_.kind(id);
    if (gyro_set_.is_excluded(id)) {
      h.state = GyroState::kExcluded;
    } else if (gate_.outlier_run(id) > 0) {
      h.state = GyroState::kSuspect;
    } else if (series_.invalid(id)) {
      h.state = GyroState::kInvalid;
    } else if (series_.absent(id)) {
      h.state = GyroState::kAbsent;
    } else {
      h.state = GyroState::kOk;
    }
  }
}

void Pipeline::Impl::start() {
  attitude_.reset(config_.initial_q_RB);
  protection_.anchor(0);
  health_.fdi_available = true;
  result_.attitude.fdi_available = true;
  frame_.index = -1;
  restart_detectors();
  update_mode(0);
}

}  // namespace tetra::fdi
