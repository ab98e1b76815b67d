// The reference's step test on its own (fdi/src/reference_step.hpp): its false-alarm rate under a good
// reference over many windows, the step it fits, and what it allows for (a calibration within its tolerance
// during a turn, a unit or reference noisier than modelled); the ramp beside the step that tells the gyros'
// common drift from the reference's step.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "reference_step.hpp"
#include "tetra/core/allan_stats.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra {
namespace {

constexpr double kSigmaRef_rad = 5.0 * kArcsecToRad;                     //!< the reference's 1σ per axis
constexpr double kAttitudeVar_rad2 = 0.7 * kArcsecToRad * kArcsecToRad;  //!< P per axis: a 1 Hz tracker's
constexpr double kS_rad2 = kSigmaRef_rad * kSigmaRef_rad + kAttitudeVar_rad2;

//! `samples` innovations of a good reference (N(0, S) per axis, times `noise_scale`), then a step of
//! `step_rad` per axis from sample `onset` on, absorbed by the filter at its gain (ρ = σ²/S per sample),
//! the calibration allowing `calibration_rad` on each axis at the onset.
fdi::detail::ReferenceStep window(std::mt19937_64& rng, int samples, double noise_scale,
                                  const Eigen::Vector3d& step_rad, int onset, double calibration_rad = 0.0) {
  fdi::detail::ReferenceStep step{fdi::PipelineConfig{}};
  std::normal_distribution<double> n01(0.0, 1.0);
  const double rho = kSigmaRef_rad * kSigmaRef_rad / kS_rad2;
  double left = 1.0;
  for (int k = 0; k < samples; ++k) {
    Eigen::Vector3d z(n01(rng), n01(rng), n01(rng));
    z *= noise_scale * std::sqrt(kS_rad2);
    if (k >= onset) {
      z += left * step_rad;
      left *= rho;
    }
    step.add(z, Eigen::Vector3d::Constant(kS_rad2), kSigmaRef_rad * kSigmaRef_rad,
             Eigen::Vector3d::Constant(k == onset ? calibration_rad : 0.0), 1.0);
  }
  return step;
}

//! `samples` innovations of a good reference at 1 Hz, with the gyros' common drift from sample `onset` on:
//! a rate error `rate_rad_s` per axis whose attitude error the filter takes at its gain (e ← ρ·e + b·1 s).
fdi::detail::ReferenceStep drift_window(std::mt19937_64& rng, int samples, const Eigen::Vector3d& rate_rad_s,
                                        int onset) {
  fdi::detail::ReferenceStep step{fdi::PipelineConfig{}};
  std::normal_distribution<double> n01(0.0, 1.0);
  const double rho = kSigmaRef_rad * kSigmaRef_rad / kS_rad2;
  Eigen::Vector3d error = Eigen::Vector3d::Zero();
  for (int k = 0; k < samples; ++k) {
    if (k >= onset) error += rate_rad_s;
    const Eigen::Vector3d z = Eigen::Vector3d(n01(rng), n01(rng), n01(rng)) * std::sqrt(kS_rad2) + error;
    error *= rho;
    step.add(z, Eigen::Vector3d::Constant(kS_rad2), kSigmaRef_rad * kSigmaRef_rad, Eigen::Vector3d::Zero(),
             1.0);
  }
  return step;
}

TEST(ReferenceStep, AGyroDriftsRampIsFitAsARampAndAReferenceStepAsAStep) {
  // The shape that tells Hdrift from Href when the step test fails (reference_step.hpp, ramp_fit): 200
  // windows of 64 samples each. A common drift of 0.3″/s from sample 10 (the step test fails in every one)
  // is fitted better by a ramp in all of them, its rate within 20 % of the drawn one in most; a reference
  // step of 20″ at sample 40 (caught in every one) better by a step in all of them. (Nearer the step test's
  // threshold the two shapes overlap: a drift of 0.15″/s fails the test in 74 of 200 windows and 20 of
  // those fit a step better; 10″ steps in 97, 2 of them a ramp better.)
  std::mt19937_64 rng(5);
  const double rate = 0.3 * kArcsecToRad;
  int drift_failed = 0, drift_as_ramp = 0, rate_close = 0;
  int step_failed = 0, step_as_step = 0;
  for (int w = 0; w < 200; ++w) {
    const auto d =
        drift_window(rng, fdi::design::reference_step_samples, Eigen::Vector3d::Constant(rate), 10);
    if (d.evaluate(d.threshold()).statistic > d.threshold()) {
      ++drift_failed;
      const auto r = d.ramp_fit();
      drift_as_ramp += r.ramp_chi2 >= r.step_chi2 ? 1 : 0;
      rate_close += (r.rate_rad_s.array() / rate - 1.0).abs().maxCoeff() < 0.2 ? 1 : 0;
    }
    const auto s = window(rng, fdi::design::reference_step_samples, 1.0,
                          Eigen::Vector3d::Constant(20.0 * kArcsecToRad / std::sqrt(3.0)), 40);
    if (s.evaluate(s.threshold()).statistic > s.threshold()) {
      ++step_failed;
      const auto r = s.ramp_fit();
      step_as_step += r.step_chi2 > r.ramp_chi2 ? 1 : 0;
    }
  }
  std::printf(
      "drift 0.3\"/s: step test failed in %d of 200, a ramp fits better in %d, rate within 20 %% in %d; "
      "step 20\": failed in %d, a step fits better in %d\n",
      drift_failed, drift_as_ramp, rate_close, step_failed, step_as_step);
  EXPECT_EQ(drift_failed, 200);
  EXPECT_EQ(drift_as_ramp, drift_failed);
  EXPECT_GE(rate_close, drift_failed / 2);
  EXPECT_EQ(step_failed, 200);
  EXPECT_EQ(step_as_step, step_failed);
}

TEST(ReferenceStep, AGoodReferenceFailsNoMoreOftenThanTheBudgetAllowsOverManyWindows) {
  // The threshold at a looser level α = 1e-2 (its union bound over the 64 onsets): a good reference's
  // windows exceed it in at most α of them; 20,000 windows put 3 standard errors at 0.2 %.
  constexpr double kAlpha = 1e-2;
  const double threshold = allan::chi2_quantile(1.0 - kAlpha / fdi::design::reference_step_samples, 3.0);
  std::mt19937_64 rng(20261207);
  int above = 0;
  constexpr int kWindows = 20000;
  for (int w = 0; w < kWindows; ++w) {
    const auto s = window(rng, fdi::design::reference_step_samples, 1.0, Eigen::Vector3d::Zero(), 0);
    above += s.evaluate(threshold).statistic > threshold ? 1 : 0;
  }
  const double rate = static_cast<double>(above) / kWindows;
  std::printf("good reference: %d of %d windows beyond the alpha = %.0e threshold (%.3f %%)\n", above,
              kWindows, kAlpha, 100.0 * rate);
  EXPECT_LE(rate, kAlpha + 3.0 * std::sqrt(kAlpha * (1.0 - kAlpha) / kWindows));
}

TEST(ReferenceStep, AStepOfTwoSigmaOfOneSampleIsFoundAtItsSize) {
  // 12″ along (1, 1, 1) (2.4σ of one sample, which no one-sample test sees) from the 20th sample of 64: the
  // fit's ĉ within 3 of its standard errors of the step on every axis over 200 seeds, the test beyond its
  // threshold in all but a few, and the share the filter took, 1 − ρ^(m − 1 − onset), reported.
  const Eigen::Vector3d step = Eigen::Vector3d::Constant(12.0 * kArcsecToRad / std::sqrt(3.0));
  std::mt19937_64 rng(7);
  int found = 0;
  int close = 0;
  for (int seed = 0; seed < 200; ++seed) {
    const auto s = window(rng, fdi::design::reference_step_samples, 1.0, step, 20);
    const fdi::detail::StepFit f = s.evaluate(s.threshold());
    found += f.statistic > s.threshold() ? 1 : 0;
    // σ(ĉ) = 1/√(Σ w g²) over the 44 samples from the onset: about 1.1″.
    close += (f.step_rad - step).cwiseAbs().maxCoeff() < 3.0 * 1.2 * kArcsecToRad ? 1 : 0;
    if (seed == 0)
      std::printf(
          "step 12 arcsec: statistic %.1f (threshold %.1f), fitted %.1f %.1f %.1f arcsec, taken %.2f\n",
          f.statistic, s.threshold(), f.step_rad.x() / kArcsecToRad, f.step_rad.y() / kArcsecToRad,
          f.step_rad.z() / kArcsecToRad, f.absorbed.x());
  }
  EXPECT_GE(found, 195);
  EXPECT_GE(close, 190);
}

TEST(ReferenceStep, ACalibrationWithinItsToleranceTurningTheBodyIsNoStep) {
  // A 20″ step while the body turned 40° (0.70 rad): what a scale-factor error of 1.4e-4 leaves in the
  // gyros' attitude. A calibration whose tolerance allows 3e-4 of the turn (43″ on each axis) makes it no
  // step; one stated exact (nothing allowed) leaves it a step.
  const Eigen::Vector3d step(20.0 * kArcsecToRad, 0.0, 0.0);
  std::mt19937_64 rng(11);
  const auto allowed =
      window(rng, fdi::design::reference_step_samples, 1.0, step, 30, 3e-4 * 40.0 * kDegToRad);
  EXPECT_LT(allowed.evaluate(allowed.threshold()).statistic, allowed.threshold());
  std::mt19937_64 same(11);
  const auto exact = window(same, fdi::design::reference_step_samples, 1.0, step, 30);
  EXPECT_GT(exact.evaluate(exact.threshold()).statistic, exact.threshold());
}

TEST(ReferenceStep, AReferenceThreeTimesNoisierThanModelledIsNoStep) {
  // Every innovation three times what S says (a noisier star tracker, or gyros noisier than their model):
  // the statistic is divided by the residual variance ratio, so the scale is the nis test's to see; no
  // window of 2,000 fails at the test's threshold.
  std::mt19937_64 rng(13);
  int above = 0;
  for (int w = 0; w < 2000; ++w) {
    const auto s = window(rng, fdi::design::reference_step_samples, 3.0, Eigen::Vector3d::Zero(), 0);
    above += s.evaluate(s.threshold()).statistic > s.threshold() ? 1 : 0;
  }
  EXPECT_EQ(above, 0);
}

TEST(ReferenceStep, TooFewSamplesJudgeNothingAndAResetEmptiesTheWindow) {
  std::mt19937_64 rng(17);
  const Eigen::Vector3d step = Eigen::Vector3d::Constant(1e-3);  // 206″: any window of three would show it
  auto s = window(rng, 2, 1.0, step, 0);
  EXPECT_EQ(s.evaluate(s.threshold()).statistic, 0.0);
  s = window(rng, 10, 1.0, step, 0);
  EXPECT_GT(s.evaluate(s.threshold()).statistic, s.threshold());
  s.reset();
  EXPECT_EQ(s.evaluate(s.threshold()).statistic, 0.0);
}

}  // namespace
}  // namespace tetra
