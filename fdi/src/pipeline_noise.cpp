// The noise model checked against the data (docs/fdi.md, "A unit noisier than its noise: section"): the
// parity's own spread (parity_spread.hpp) — between consecutive epochs (one sample's noise: the χ², the jump
// test) and between consecutive block sums (the white noise every sum sees: the CUSUM, the GLT, sigma) —
// rejects the stated noise, and the model takes what the data show, says so, and the detectors start again on
// it.

#include <cmath>
#include <cstdio>
#include <limits>

#include "pipeline_impl.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi {

void Pipeline::Impl::check_noise_model() {
  const auto found =
      sample_spread_.observe(gate_.spread_sample(), gate_.spread_dof(), gate_.spread_cap(), frame_.now_ns);
  bias_match_.set_white_ratio(shown_white_ratio());
  if (!found) return;
  if (subsets_.quantization_share() <= design::spread_white_dominates) white_spread_.raise_to(found->ratio);
  widen_noise(*found, "between consecutive epochs (one sample's noise)");
}

void Pipeline::Impl::check_long_run_noise() {
  if (!parity_ran_) return;
  // A fault's mean change is not noise: no block sums while an episode is open.
  if (isolator_.episode().active) {
    blocks_.restart();
    return;
  }
  const GyroMask active = gyro_set_.active();
  const Subset& s = subsets_.get(active);
  const int m = long_run_block_epochs();
  // A block's sums need the same gyros on consecutive epochs; the body's motion cancels in the parity, and
  // what the calibration's error makes of it varies slowly enough for a second difference to cancel.
  const bool clean = gate_.consecutive() && frame_.usable == active;
  if (!blocks_.add(detector_.parity_measured().data(), s.dof, active, clean, m)) return;
  const double q = subsets_.block_quantization(s, m);
  const auto found = white_spread_.observe(blocks_.u(), s.dof, long_run_cap(s), frame_.now_ns, q);
  if (found) widen_noise(*found, "between 5-s sums (the white noise every sum sees)");
}

double Pipeline::Impl::shown_white_ratio() const {
  // One sample shows the white noise where the quantization is a small share of it (as for raise_to above);
  // else the block sums do.
  const ParitySpread& spread =
      subsets_.quantization_share() <= design::spread_white_dominates ? sample_spread_ : white_spread_;
  return std::min(1.0, spread.measured() / spread.ratio());
}

double Pipeline::Impl::long_run_cap(const Subset& s) const {
  // A value beyond the test's own χ² threshold (times the quantization's share) is a step, not noise:
  // censored at it.
  const double q = subsets_.block_quantization(s, long_run_block_epochs());
  return s.spread_threshold * (1.0 + q / s.dof);
}

int Pipeline::Impl::long_run_block_epochs() const {
  return std::max(2, static_cast<int>(std::lround(design::spread_block_s / subsets_.period_s())));
}

void Pipeline::Impl::widen_noise(const SpreadFinding& f, const char* evidence) {
  subsets_.set_noise_ratios(white_spread_.ratio(), sample_spread_.ratio());
  noise_match_.set_common_ratio(white_spread_.ratio(), attitude_.filter());
  attitude_.filter().set_bias_model_ratio(white_spread_.ratio());
  calibration_fit_.restart_block();
  blocks_.restart();
  const bool episode = isolator_.episode().active;
  // The detectors' statistics are in units of the model before: they start again on the new one.
  restart_detectors();
  emit_noise_widened(f, evidence);
  if (episode) emit_episode_explained(f);
}

FdiEvent Pipeline::Impl::model_rejected(EvidenceSource source, double statistic, double threshold) const {
  FdiEvent e = event_now(EventType::kNoiseModel);
  e.statistic = statistic;
  e.ledger.push_back(stated(source, kHypothesisNone, RowVerdict::kRejected, statistic, threshold));
  return e;
}

void Pipeline::Impl::emit_noise_widened(const SpreadFinding& f, const char* evidence) {
  // H0 here is "the noise as stated": rejected by the spread; which gyro is noisier, the parity cannot tell,
  // so every gyro's noise is taken the same.
  FdiEvent e = model_rejected(EvidenceSource::kParitySpread, f.statistic, f.threshold);
  char text[400];
  std::snprintf(text, sizeof text,
                "the parity's spread %s is %.3g times the model's over %d samples: every gyro's white noise "
                "is taken as %.3g times its stated variance from now on (every sum and sigma), one sample's "
                "noise as at least %.3g times (the parity cannot tell which gyro)",
                evidence, f.estimate, f.samples, subsets_.white_ratio(), subsets_.sample_ratio());
  e.detail = text;
  emit(std::move(e));
}

void Pipeline::Impl::emit_block_matched(const BlockFinding& f) {
  // H0 here is "the bias model as stated": rejected by the blocks; which gyro, the parity's columns cannot
  // always tell, so every gyro's model opens by what its own hypothesis needs.
  FdiEvent e = model_rejected(EvidenceSource::kParityBlockMatch, f.statistic, f.threshold);
  char text[320];
  std::snprintf(text, sizeof text,
                "a slow rate error beyond the bias model in the parity's %.0f-s block means of the filter's "
                "innovations (gyro %d's block %.3g times the variance the model predicts): every gyro's bias "
                "model opened by what its own hypothesis needs (sigma carries it); nothing excluded",
                design::parity_bias_block_s, f.gyro, f.ratio);
  e.detail = text;
  emit(std::move(e));
}

void Pipeline::Impl::emit_episode_explained(const SpreadFinding& f) {
  FdiEvent c = event_now(EventType::kCleared);
  c.detail =
      "the episode's alarm was judged on a noise the data reject (noise_model): the detectors start "
      "again on the noise the data show; sigma keeps what the episode added";
  c.ledger.push_back(stated(EvidenceSource::kParitySpread, kHypothesisNone, RowVerdict::kConsistent,
                            f.statistic, f.threshold));
  emit(std::move(c));
}

}  // namespace tetra::fdi
