#include "tetra/sim/perturbation_families.hpp"

#include <array>
#include <cmath>
#include <cstdio>

#include <Eigen/LU>

#include "tetra/core/units.hpp"
#include "tetra/sim/random.hpp"

namespace tetra::sim {

namespace {

constexpr std::array<std::string_view, kFamilyCount> kFamilyNames = {
    "fault-in-slew", "data-path", "gap",        "reference", "calibration", "calibration-without-noise",
    "second-fault",  "warm-up",   "data-sheet", "noisy-unit"};

constexpr double kSlewStart_s = 30.0;                //!< [s] the detectors have a full history by then
constexpr double kConfiguredReference_arcsec = 5.0;  //!< [arcsec] the star tracker's stated 1σ
//! [s] every run goes on this long after its perturbation: sigma's honesty is judged per run, and a run's
//! attitude error is correlated over tens of seconds with the reference, so a short run's NEES is a χ² of
//! few degrees of freedom.
constexpr double kAfter_s = 600.0;

//! The draws of one run: a stream of its own, a function of (family, seed, index) alone.
Rng family_rng(Family family, std::uint64_t seed, std::uint64_t index) {
  return Rng(
      splitmix64(splitmix64(splitmix64(seed) ^ ((static_cast<std::uint64_t>(family) + 1) << 40)) ^ index));
}

double between(Rng& rng, double lo, double hi) {
  return lo + (hi - lo) * rng.uniform();
}
int pick(Rng& rng, int count) {
  return static_cast<int>(rng.uniform() * count) % count;
}

//! Body axis ±X, ±Y, ±Z by `which` (0…5).
Eigen::Vector3d signed_axis(int which) {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  a[which % 3] = which >= 3 ? -1.0 : 1.0;
  return a;
}

//! The quiet base: gentle attitude control (0.04°, 1e-4 deg/s²), the 5″ reference at 1 Hz or none.
Scenario base(int n, bool reference, double duration_s) {
  Scenario sc;
  sc.name = "perturbed";
  sc.motion.kind = MotionKind::kSlews;
  sc.motion.orbit_period_s = 6000.0;
  sc.motion.acs.amplitude_deg = 0.04;
  sc.motion.acs.peak_accel_dps2 = 1e-4;
  sc.rate_hz = 10.0;
  sc.duration_s = duration_s;
  sc.unit = unit_with_gyros(n);
  sc.reference.rate_hz = reference ? 1.0 : 0.0;
  sc.reference.noise_arcsec = kConfiguredReference_arcsec;
  return sc;
}

//! An agile slew from kSlewStart_s: 30–45° in 10–15 s about ±X, ±Y or ±Z (peak 2Φ/T deg/s).
Slew agile_slew(Rng& rng, int axis_index) {
  return {signed_axis(axis_index), between(rng, 30.0, 45.0), kSlewStart_s, between(rng, 10.0, 15.0)};
}

//! [deg/s²] a slew's peak acceleration, 2πΦ/T² (the simulator's smooth profile).
double peak_acceleration(const Slew& s) {
  return 2.0 * kPi * std::abs(s.angle_deg) / (s.duration_s * s.duration_s);
}

FaultSpec make_fault(int gyro, FaultKind kind, double at_s, double size) {
  FaultSpec f;
  f.gyro = gyro;
  f.kind = kind;
  f.at_s = at_s;
  f.size = size;
  return f;
}

std::string axis_text(const Eigen::Vector3d& a) {
  char text[48];
  std::snprintf(text, sizeof text, "(%.0f,%.0f,%.0f)", a.x(), a.y(), a.z());
  return text;
}

std::string slew_text(const Slew& s) {
  char text[80];
  std::snprintf(text, sizeof text, "%.1fdeg/%.1fs about %s", s.angle_deg, s.duration_s,
                axis_text(s.axis_B).c_str());
  return text;
}

std::string fault_text(const FaultSpec& f) {
  return format_fault_spec(f);
}

//! The fault kinds of a single fault in a slew: the audit's stuck and 0 V, a large and a small bias step,
//! noise ×10, a fast ramp and a +5 % scale change.
FaultSpec slew_fault(Rng& rng, int kind_index, int gyro, double at_s) {
  const double sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
  switch (kind_index % 7) {
    case 0:
      return make_fault(gyro, FaultKind::kStuck, at_s, 0.0);
    case 1:
      return make_fault(gyro, FaultKind::kZero, at_s, 0.0);
    case 2:
      return make_fault(gyro, FaultKind::kBias, at_s, sign * between(rng, 1e-2, 3e-2));
    case 3:
      return make_fault(gyro, FaultKind::kBias, at_s, sign * between(rng, 1e-3, 3e-3));
    case 4:
      return make_fault(gyro, FaultKind::kNoise, at_s, between(rng, 5.0, 10.0));
    case 5:
      return make_fault(gyro, FaultKind::kRamp, at_s, sign * between(rng, 3e-4, 1e-3));
    default:
      return make_fault(gyro, FaultKind::kScale, at_s, sign * between(rng, 0.02, 0.05));
  }
}

PerturbedRun fault_in_slew(Rng& rng, std::uint64_t index) {
  static constexpr std::array<const char*, 3> kWhen = {"start", "middle", "end"};
  const int when = static_cast<int>(index % 3);
  const int kind = static_cast<int>(index / 3 % 7);
  const int n = 4 + static_cast<int>(index / 21 % 3);
  const bool reference = index / 63 % 2 == 1;
  PerturbedRun r;
  const Slew slew = agile_slew(rng, pick(rng, 6));
  r.scenario = base(n, reference, kSlewStart_s + slew.duration_s + kAfter_s);
  r.scenario.motion.slews = {slew};
  const double at = kSlewStart_s + 0.5 * when * slew.duration_s;
  r.options.faults = {slew_fault(rng, kind, 1 + pick(rng, n), at)};
  r.max_angular_acceleration_dps2 = rng.uniform() < 0.5 ? 2e-4 : 1e-3;
  static constexpr std::array<const char*, 7> kSlewCaseNames = {
      "stuck", "zero", "bias 1e-2..3e-2", "bias 1e-3..3e-3", "noise", "ramp", "scale"};
  r.case_name = std::string(kSlewCaseNames[static_cast<std::size_t>(kind)]) + " at the " +
                kWhen[static_cast<std::size_t>(when)];
  r.label = "N=" + std::to_string(n) + " " + fault_text(r.options.faults[0]) + " at the " +
            kWhen[static_cast<std::size_t>(when)] + " of " + slew_text(slew) + (reference ? " ref" : "");
  return r;
}

PerturbedRun data_path(Rng& rng, std::uint64_t index) {
  const int n = 4 + static_cast<int>(index % 3);
  const bool reference = index / 3 % 2 == 1;
  PerturbedRun r;
  const Slew slew = agile_slew(rng, pick(rng, 6));
  r.scenario = base(n, reference, kSlewStart_s + slew.duration_s + kAfter_s);
  r.scenario.motion.slews = {slew};
  r.scenario.drop_probability = between(rng, 0.0, 0.2);
  r.scenario.jitter_s = between(rng, 0.0, 0.005);
  r.sample_period_s = 0.1;  // as a service with jitter configures it
  r.max_angular_acceleration_dps2 = rng.uniform() < 0.5 ? 2e-4 : 1e-3;
  char text[96];
  std::snprintf(text, sizeof text, " drop %.3f jitter %.4f s", r.scenario.drop_probability,
                r.scenario.jitter_s);
  r.case_name = reference ? "drops and jitter, reference" : "drops and jitter";
  r.label = "N=" + std::to_string(n) + " " + slew_text(slew) + text + (reference ? " ref" : "");
  return r;
}

PerturbedRun gap(Rng& rng, std::uint64_t index) {
  const int n = 4 + static_cast<int>(index % 3);
  const bool reference = index / 3 % 2 == 1;
  const bool orbit = index / 6 % 3 == 0;
  PerturbedRun r;
  const Slew slew = agile_slew(rng, pick(rng, 6));
  const double length = between(rng, 10.0, 30.0);
  r.scenario = base(n, reference, kSlewStart_s + slew.duration_s + length + kAfter_s);
  if (!orbit) {
    r.scenario.motion.slews = {slew};
    r.max_angular_acceleration_dps2 = peak_acceleration(slew);  // the bound the gap's widening rests on
  }
  r.gap_from_s = orbit ? 40.0 : kSlewStart_s + between(rng, 0.2, 0.8) * slew.duration_s;
  r.gap_until_s = r.gap_from_s + length;
  char text[96];
  std::snprintf(text, sizeof text, " gap %.1f s from %.1f s", length, r.gap_from_s);
  r.case_name = std::string(orbit ? "orbit" : "mid-slew") + (reference ? ", reference" : "");
  r.label = "N=" + std::to_string(n) + " " + (orbit ? std::string("orbit") : slew_text(slew)) + text +
            (reference ? " ref" : "");
  return r;
}

PerturbedRun reference_failure(Rng& rng, std::uint64_t index) {
  const auto failure = static_cast<ReferenceFailure>(1 + index % 5);
  const int n = 4 + static_cast<int>(index / 5 % 3);
  PerturbedRun r;
  r.reference_failure = failure;
  // A slew about a random axis early in the run (a late reference shows only while the rate changes).
  Slew slew = agile_slew(rng, pick(rng, 6));
  slew.duration_s = between(rng, 10.0, 20.0);
  r.scenario = base(n, true, 150.0 + kAfter_s);
  r.scenario.motion.slews = {slew};
  auto& ref = r.scenario.reference;
  char text[128] = "";
  switch (failure) {
    case ReferenceFailure::kLate:
      ref.latency_s = between(rng, 0.1, 0.3);
      std::snprintf(text, sizeof text, "late %.3f s", ref.latency_s);
      break;
    case ReferenceFailure::kNoisy:
      ref.noise_arcsec = kConfiguredReference_arcsec * between(rng, 3.0, 5.0);
      std::snprintf(text, sizeof text, "noise %.1f arcsec (5 configured)", ref.noise_arcsec);
      break;
    case ReferenceFailure::kBiasStep:
    case ReferenceFailure::kBiasRamp:
      ref.bias_arcsec = (rng.uniform() < 0.5 ? -1.0 : 1.0) * between(rng, 10.0, 40.0);
      ref.bias_at_s = between(rng, 60.0, 120.0);
      ref.bias_ramp_s = failure == ReferenceFailure::kBiasRamp ? between(rng, 20.0, 60.0) : 0.0;
      r.reference_fault_at_s = ref.bias_at_s;
      std::snprintf(text, sizeof text, "bias %.1f arcsec from %.1f s over %.1f s", ref.bias_arcsec,
                    ref.bias_at_s, ref.bias_ramp_s);
      break;
    default:
      ref.misid_deg = between(rng, 0.2, 1.0);
      ref.misid_at_s = between(rng, 60.0, 150.0);
      ref.misid_duration_s = between(rng, 5.0, 20.0);
      r.reference_fault_at_s = ref.misid_at_s;
      std::snprintf(text, sizeof text, "mis-identified %.2f deg from %.1f s for %.1f s", ref.misid_deg,
                    ref.misid_at_s, ref.misid_duration_s);
      break;
  }
  r.case_name = std::string(reference_failure_name(failure));
  r.label = "N=" + std::to_string(n) + " " + slew_text(slew) + " reference " +
            std::string(reference_failure_name(failure)) + ": " + text;
  return r;
}

//! A third of the calibration families' runs carry a gyro fault (at the first slew's start, in its middle or
//! between the slews): the perturbation must not hide it nor blame another gyro.
void maybe_fault(Rng& rng, std::uint64_t index, int n, const Slew& slew, PerturbedRun& r) {
  if (index % 3 != 0) return;
  const int gyro = 1 + pick(rng, n);
  switch (index / 3 % 3) {
    case 0:
      r.options.faults = {make_fault(gyro, FaultKind::kStuck, slew.start_s, 0.0)};
      break;
    case 1:
      r.options.faults = {make_fault(gyro, FaultKind::kZero, slew.start_s + 0.5 * slew.duration_s, 0.0)};
      break;
    default:
      r.options.faults = {make_fault(gyro, FaultKind::kBias, slew.start_s + slew.duration_s + 10.0, 1e-2)};
      break;
  }
  r.label += " " + fault_text(r.options.faults[0]);
  r.case_name = std::string(fault_kind_name(r.options.faults[0].kind));
}

PerturbedRun calibration(Rng& rng, std::uint64_t index, bool stated_noise) {
  const int n = 4 + static_cast<int>(index / 9 % 3);
  const bool reference = index / 27 % 2 == 1;
  PerturbedRun r;
  Slew slew = agile_slew(rng, pick(rng, 6));
  slew.duration_s = between(rng, 10.0, 15.0);
  Slew back = slew;
  back.angle_deg = -slew.angle_deg;
  back.start_s = slew.start_s + slew.duration_s + 30.0;
  r.scenario = base(n, reference, back.start_s + back.duration_s + kAfter_s);
  r.scenario.motion.slews = {slew, back};
  char text[128];
  if (stated_noise) {
    r.stated_sigma_multiple = between(rng, 0.5, 2.0);
    const double axis_sigma = between(rng, 3e-4, 1e-3);
    r.calibration = stated_calibration(r.scenario.unit, r.stated_sigma_multiple, 1e-3, axis_sigma,
                                       splitmix64(index) ^ static_cast<std::uint64_t>(rng.uniform() * 1e9));
    std::snprintf(text, sizeof text, " calibration off by %.2f stated sigma (axis sigma %.1e)",
                  r.stated_sigma_multiple, axis_sigma);
  } else {
    r.calibration = r.scenario.unit;
    for (auto& g : r.calibration.gyros) g.noise.reset();
    std::snprintf(text, sizeof text, " calibration without noise:");
  }
  r.label = "N=" + std::to_string(n) + " " + slew_text(slew) + " and back" + text + (reference ? " ref" : "");
  r.case_name = "fault-free";
  maybe_fault(rng, index, n, slew, r);
  return r;
}

//! Bias steps on gyros `a` and `b` of a four-gyro unit that cancel in its parity (f_b = −f_a·v_a/v_b, v the
//! unit's parity vector).
std::vector<FaultSpec> parity_cancelling(const Calibration& unit, int a, int b, double size, double at_s) {
  Eigen::MatrixXd h(static_cast<Eigen::Index>(unit.gyros.size()), 3);
  for (std::size_t i = 0; i < unit.gyros.size(); ++i)
    h.row(static_cast<Eigen::Index>(i)) = unit.gyros[i].axis_B.normalized().transpose();
  const Eigen::VectorXd v = Eigen::FullPivLU<Eigen::MatrixXd>(h.transpose()).kernel().col(0);
  return {make_fault(a, FaultKind::kBias, at_s, size),
          make_fault(b, FaultKind::kBias, at_s, -size * v[a - 1] / v[b - 1])};
}

PerturbedRun second_fault(Rng& rng, std::uint64_t index) {
  const int kind = static_cast<int>(index % 4);
  PerturbedRun r;
  const double at = between(rng, 40.0, 80.0);
  const double sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
  r.scenario = base(kind == 3 ? 4 : 3, true, 80.0 + kAfter_s);
  r.scenario.motion.kind = MotionKind::kOrbit;
  const int gyro = 1 + pick(rng, 3);
  switch (kind) {
    case 0:
      r.options.faults = {make_fault(gyro, FaultKind::kBias, at, sign * between(rng, 3e-4, 1e-3))};
      break;
    case 1:
      r.options.faults = {make_fault(gyro, FaultKind::kRamp, at, sign * between(rng, 1e-6, 1e-5))};
      break;
    case 2:
      r.options.faults = {make_fault(gyro, FaultKind::kNoise, at, between(rng, 5.0, 10.0))};
      break;
    default: {
      const int other = 1 + (gyro % 3);  // two of gyros 1..3, both faulty: no parity left to see them
      r.options.faults = parity_cancelling(r.scenario.unit, gyro, other, sign * between(rng, 3e-4, 1e-3), at);
      break;
    }
  }
  static constexpr std::array<const char*, 4> kEdgeCaseNames = {
      "bias 3e-4..1e-3", "ramp 1e-6..1e-5", "noise x5..x10", "two biases cancelling in the parity"};
  r.case_name = kEdgeCaseNames[static_cast<std::size_t>(kind)];
  r.label = std::string(kind == 3 ? "N=4, two biases cancelling in the parity:" : "N=3:");
  for (const auto& f : r.options.faults) r.label += " " + fault_text(f);
  r.label += " ref, orbit";
  return r;
}

//! A warm-up from switch-on: 10–25 K in a first-order transient of τ = 120–600 s, each gyro's bias moving by
//! its own coefficient (a common part of 0.5–2e-6 deg/s/K with a random sign, each gyro 0.5–1.5× it), so 5e-6
//! to 8e-5 deg/s at the start, below every detector; an orbit with gentle attitude control and one agile slew
//! at 3τ/4. A third of the runs carry a gyro fault (maybe_fault, around the slew).
PerturbedRun warm_up(Rng& rng, std::uint64_t index) {
  const int n = 4 + static_cast<int>(index / 9 % 3);
  const bool reference = index / 27 % 2 == 1;
  PerturbedRun r;
  ThermalOptions t;
  t.end_C = 20.0;
  t.start_C = t.end_C - between(rng, 10.0, 25.0);
  t.time_constant_s = between(rng, 120.0, 600.0);
  const double common = (rng.uniform() < 0.5 ? -1.0 : 1.0) * between(rng, 0.5e-6, 2e-6);
  for (int i = 0; i < n; ++i) t.bias_dps_per_K.push_back(common * between(rng, 0.5, 1.5));
  Slew slew = agile_slew(rng, pick(rng, 6));
  slew.start_s = 0.75 * t.time_constant_s;
  r.scenario = base(n, reference, 3.0 * t.time_constant_s + kAfter_s);
  r.scenario.motion.slews = {slew};
  r.scenario.thermal = t;
  char text[160];
  std::snprintf(text, sizeof text, " warm-up %.1f to %.1f degC, tau %.0f s, %.2e deg/s/K common,", t.start_C,
                t.end_C, t.time_constant_s, common);
  r.label = "N=" + std::to_string(n) + text + " " + slew_text(slew) + (reference ? " ref" : "");
  r.case_name = reference ? "fault-free, reference" : "fault-free";
  maybe_fault(rng, index, n, slew, r);
  if (!r.options.faults.empty() && reference) r.case_name += ", reference";
  return r;
}

//! A unit flown on its data sheet: the fusion's calibration has every scale factor 10–30 % off (random
//! sign), every axis 2–10 mrad off, biases off by 1e-3 V, no sigma: and no noise: section (a data sheet
//! states neither). The motion: slews of 20–40° in 20 s about X, Y and Z in turn, one every 100 s, so
//! that every block of the motion fit sees the rate vary about every axis. A third of the runs carry a
//! gyro fault (maybe_fault, around the first slew).
PerturbedRun data_sheet(Rng& rng, std::uint64_t index) {
  const int n = 4 + static_cast<int>(index / 9 % 3);
  const bool reference = index / 27 % 2 == 1;
  PerturbedRun r;
  r.scenario = base(n, reference, 1200.0);
  for (int k = 0; k < 11; ++k) {
    const double sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
    r.scenario.motion.slews.push_back(
        {signed_axis(2 * (k % 3)), sign * between(rng, 20.0, 40.0), kSlewStart_s + 100.0 * k, 20.0});
  }
  r.calibration = r.scenario.unit;
  double worst = 0.0;
  for (auto& g : r.calibration.gyros) {
    const double off = (rng.uniform() < 0.5 ? -1.0 : 1.0) * between(rng, 0.1, 0.3);
    worst = std::max(worst, std::abs(off));
    g.scale_factor_V_per_dps *= 1.0 + off;
    Eigen::Vector3d d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    d -= g.axis_B * g.axis_B.dot(d);
    g.axis_B = (g.axis_B + between(rng, 2e-3, 1e-2) * d.normalized()).normalized();
    g.bias_V += (rng.uniform() < 0.5 ? -1e-3 : 1e-3);
    g.sigma.reset();
    g.noise.reset();
  }
  char text[96];
  std::snprintf(text, sizeof text, " data-sheet calibration (scale factors up to %.0f %% off)",
                100.0 * worst);
  r.label = "N=" + std::to_string(n) + " eleven slews about X, Y, Z" + text + (reference ? " ref" : "");
  r.case_name = "fault-free";
  maybe_fault(rng, index, n, r.scenario.motion.slews.front(), r);
  return r;
}

//! A unit noisier (or quieter) than its noise: section says: the unit's true white noise N and bias
//! instability B each at a common 0.5–3 times the stated terms, each gyro's within ±25 % of that (a gyro
//! several times noisier than its peers is a noise fault, the noise-level test's), the fusion given the
//! stated terms; a slew and back. A third of the runs carry a gyro fault (maybe_fault).
PerturbedRun noisy_unit(Rng& rng, std::uint64_t index) {
  const int n = 4 + static_cast<int>(index / 9 % 3);
  const bool reference = index / 27 % 2 == 1;
  PerturbedRun r;
  Slew slew = agile_slew(rng, pick(rng, 6));
  Slew back = slew;
  back.angle_deg = -slew.angle_deg;
  back.start_s = slew.start_s + slew.duration_s + 30.0;
  r.scenario = base(n, reference, back.start_s + back.duration_s + kAfter_s);
  r.scenario.motion.slews = {slew, back};
  r.calibration = r.scenario.unit;
  const double white = between(rng, 0.5, 3.0);
  const double instability = between(rng, 0.5, 3.0);
  for (auto& g : r.scenario.unit.gyros) {
    if (!g.noise) continue;
    if (g.noise->arw_dps_rtHz) *g.noise->arw_dps_rtHz *= white * between(rng, 0.8, 1.25);
    if (g.noise->bias_instability_dps)
      *g.noise->bias_instability_dps *= instability * between(rng, 0.8, 1.25);
  }
  char text[96];
  std::snprintf(text, sizeof text, " white noise %.2f x, bias instability %.2f x stated", white, instability);
  r.label = "N=" + std::to_string(n) + " " + slew_text(slew) + " and back" + text + (reference ? " ref" : "");
  r.case_name = "fault-free";
  maybe_fault(rng, index, n, slew, r);
  return r;
}

}  // namespace

std::string_view family_name(Family family) {
  return kFamilyNames[static_cast<std::size_t>(family)];
}

std::optional<Family> family_from_name(std::string_view name) {
  for (int i = 0; i < kFamilyCount; ++i)
    if (kFamilyNames[static_cast<std::size_t>(i)] == name) return static_cast<Family>(i);
  return std::nullopt;
}

std::vector<Family> all_families() {
  std::vector<Family> out;
  for (int i = 0; i < kFamilyCount; ++i) out.push_back(static_cast<Family>(i));
  return out;
}

std::string_view reference_failure_name(ReferenceFailure failure) {
  switch (failure) {
    case ReferenceFailure::kNone:
      return "none";
    case ReferenceFailure::kLate:
      return "late";
    case ReferenceFailure::kNoisy:
      return "noisy";
    case ReferenceFailure::kBiasStep:
      return "bias-step";
    case ReferenceFailure::kBiasRamp:
      return "bias-ramp";
    case ReferenceFailure::kMisidentified:
      return "mis-identified";
  }
  return "none";
}

Calibration unit_with_gyros(int n) {
  Calibration cal = seed_as_built_unit();
  const GyroCalibration first = cal.gyros[0];
  const auto extra = [&cal, &first](int id, const Eigen::Vector3d& axis) {
    cal.gyros.push_back(first);
    GyroCalibration& g = cal.gyros.back();
    g.id = id;
    g.scale_factor_V_per_dps = 0.08 + 0.001 * id;
    g.bias_V = 1e-4 * id;
    g.axis_B = axis.normalized();
  };
  if (n == 3) cal.gyros.resize(3);
  if (n >= 5) extra(5, Eigen::Vector3d(0.3, 0.5, -0.6));
  if (n >= 6) extra(6, Eigen::Vector3d(-0.4, 0.7, 0.2));
  return cal;
}

Calibration stated_calibration(const Calibration& truth, double errors, double scale_sigma, double axis_sigma,
                               std::uint64_t seed) {
  Calibration cal = truth;
  Rng rng(splitmix64(seed));
  for (auto& g : cal.gyros) {
    const Eigen::Vector3d a = g.axis_B;
    Eigen::Vector3d d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    d -= a * a.dot(d);
    d *= errors * axis_sigma / d.cwiseAbs().maxCoeff();
    g.axis_B = (a + d).normalized();  // renormalizing moves it by O(σ²)
    g.scale_factor_V_per_dps *= 1.0 + (g.id % 2 == 0 ? 1.0 : -1.0) * errors * scale_sigma;
    GyroSigma s;
    s.scale_factor_V_per_dps = scale_sigma * std::abs(g.scale_factor_V_per_dps);
    s.bias_V = 1e-6;
    s.axis = Eigen::Vector3d::Constant(axis_sigma);
    g.sigma = s;
  }
  return cal;
}

PerturbedRun unperturbed_twin(const PerturbedRun& run) {
  PerturbedRun twin = run;
  twin.label = "twin of " + run.label;
  twin.options.faults.clear();
  twin.scenario.faults.clear();
  twin.scenario.drop_probability = 0.0;
  twin.scenario.jitter_s = 0.0;
  twin.gap_from_s = twin.gap_until_s = 0.0;
  const double rate_hz = run.scenario.reference.rate_hz;
  twin.scenario.reference = ReferenceOptions{};
  twin.scenario.reference.rate_hz = rate_hz;
  twin.scenario.reference.noise_arcsec = kConfiguredReference_arcsec;
  twin.reference_failure = ReferenceFailure::kNone;
  twin.reference_fault_at_s = -1.0;
  twin.calibration = run.scenario.unit;
  twin.stated_sigma_multiple = 0.0;
  twin.scenario.thermal = ThermalOptions{};
  return twin;
}

PerturbedRun perturbed_run(Family family, std::uint64_t seed, std::uint64_t index) {
  Rng rng = family_rng(family, seed, index);
  PerturbedRun r;
  switch (family) {
    case Family::kFaultInSlew:
      r = fault_in_slew(rng, index);
      break;
    case Family::kDataPath:
      r = data_path(rng, index);
      break;
    case Family::kGap:
      r = gap(rng, index);
      break;
    case Family::kReference:
      r = reference_failure(rng, index);
      break;
    case Family::kCalibration:
      r = calibration(rng, index, true);
      break;
    case Family::kCalibrationWithoutNoise:
      r = calibration(rng, index, false);
      break;
    case Family::kSecondFault:
      r = second_fault(rng, index);
      break;
    case Family::kWarmUp:
      r = warm_up(rng, index);
      break;
    case Family::kDataSheet:
      r = data_sheet(rng, index);
      break;
    case Family::kNoisyUnit:
      r = noisy_unit(rng, index);
      break;
  }
  if (r.calibration.gyros.empty()) r.calibration = r.scenario.unit;
  r.family = family;
  r.options.seed = splitmix64(static_cast<std::uint64_t>(rng.uniform() * 9007199254740992.0));
  r.label = std::string(family_name(family)) + " #" + std::to_string(index) + " seed " +
            std::to_string(seed) + ": " + r.label;
  return r;
}

}  // namespace tetra::sim
