#include "tetra/sim/dispersion.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <yaml-cpp/yaml.h>
#include <Eigen/Geometry>

#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/units.hpp"
#include "tetra/core/yaml_reader.hpp"
#include "tetra/sim/random.hpp"
#include "text.hpp"

namespace tetra::sim {

namespace {

using P = DispersedParameter;

enum class Shape { kPerGyro, kPerGyroXyz, kXyz, kScalar };
//! What the support of a parameter's distribution must lie in.
enum class Domain {
  kAny,            //!< any real (normal allowed)
  kNonNegative,    //!< [0, ∞): a noise factor, a noise, a latency
  kProbability,    //!< [0, 1)
  kAboveMinus100,  //!< (−100, ∞) and bounded below: a percent change of inertia
  kBounded,        //!< a finite support (checked against every scenario)
  kChoice,         //!< choice only
};

struct ParamInfo {
  P parameter;
  const char* name;
  Shape shape;
  Domain domain;
  bool calibration;  //!< `calibration` (the 1σ of the calibration) allowed
};

constexpr ParamInfo kParams[] = {
    {P::kScaleFactorPpm, "unit.scale_factor_ppm", Shape::kPerGyro, Domain::kAny, true},
    {P::kBiasV, "unit.bias_V", Shape::kPerGyro, Domain::kAny, true},
    {P::kAxis, "unit.axis", Shape::kPerGyroXyz, Domain::kAny, true},
    {P::kArwFactor, "unit.arw_factor", Shape::kPerGyro, Domain::kNonNegative, false},
    {P::kBiasInstabilityFactor, "unit.bias_instability_factor", Shape::kPerGyro, Domain::kNonNegative, false},
    {P::kRateRandomWalkFactor, "unit.rate_random_walk_factor", Shape::kPerGyro, Domain::kNonNegative, false},
    {P::kQuantizationFactor, "unit.quantization_factor", Shape::kPerGyro, Domain::kNonNegative, false},
    {P::kInertiaPercent, "spacecraft.inertia_percent", Shape::kXyz, Domain::kAboveMinus100, false},
    {P::kInertiaAxesDeg, "spacecraft.inertia_axes_deg", Shape::kXyz, Domain::kAny, false},
    {P::kDisturbanceConstantNm, "disturbance.constant_Nm", Shape::kXyz, Domain::kAny, false},
    {P::kDisturbancePeriodicNm, "disturbance.periodic_Nm", Shape::kXyz, Domain::kAny, false},
    {P::kReferenceNoiseArcsec, "reference.noise_arcsec", Shape::kScalar, Domain::kNonNegative, false},
    {P::kReferenceBiasArcsec, "reference.bias_arcsec", Shape::kScalar, Domain::kAny, false},
    {P::kReferenceLatencyS, "reference.latency_s", Shape::kScalar, Domain::kNonNegative, false},
    {P::kReferenceDropProbability, "reference.drop_probability", Shape::kScalar, Domain::kProbability, false},
    {P::kDropProbability, "data.drop_probability", Shape::kScalar, Domain::kProbability, false},
    {P::kJitterS, "data.jitter_s", Shape::kScalar, Domain::kNonNegative, false},
    {P::kFaultOnsetS, "fault.onset_s", Shape::kScalar, Domain::kBounded, false},
    {P::kFaultSizeFactor, "fault.size_factor", Shape::kScalar, Domain::kBounded, false},
    {P::kFaultGyro, "fault.gyro", Shape::kScalar, Domain::kChoice, false},
    {P::kFaultKind, "fault.kind", Shape::kScalar, Domain::kChoice, false},
    {P::kThermalBiasDpsPerK, "thermal.bias_dps_per_K", Shape::kPerGyro, Domain::kBounded, false},
    {P::kThermalStartC, "thermal.start_C", Shape::kScalar, Domain::kBounded, false},
    {P::kRateRampDps2, "unit.rate_ramp_dps2", Shape::kPerGyro, Domain::kBounded, false},
};

const ParamInfo& info_of(P p) {
  for (const ParamInfo& i : kParams) {
    if (i.parameter == p) return i;
  }
  return kParams[0];  // not reached: every parameter is in the table
}

std::string allowed_names() {
  std::string out;
  for (const ParamInfo& i : kParams) out += (out.empty() ? "" : ", ") + std::string(i.name);
  return out;
}

//! [numbers] of a distribution's list, as "what.kind: expected [a, b]" errors otherwise.
Result<std::vector<double>> numbers_of(const YamlReader& yaml, const YAML::Node& list,
                                       const std::string& what, std::size_t count, const char* form) {
  if (!list.IsSequence() || list.size() != count)
    return yaml.error(list, what, std::string("expected ") + form);
  std::vector<double> out;
  for (std::size_t i = 0; i < count; ++i) {
    auto v = yaml.number(list[i], what + "[" + std::to_string(i) + "]");
    if (!v) return v.error();
    out.push_back(*v);
  }
  return out;
}

//! The support [min, max] a domain asks for, as a message ("" when it fits).
std::string domain_problem(Domain domain, const Distribution& d) {
  switch (domain) {
    case Domain::kAny:
      return "";
    case Domain::kNonNegative:
      return d.min >= 0.0 ? ""
                          : "its values must not be negative (use uniform, log_uniform or "
                            "truncated_normal with min >= 0)";
    case Domain::kProbability:
      return d.min >= 0.0 && d.max < 1.0 ? "" : "its values must lie in [0, 1) (uniform or truncated_normal)";
    case Domain::kAboveMinus100:
      return d.min > -100.0 ? "" : "its values must stay above -100 % (uniform or truncated_normal)";
    case Domain::kBounded:
      return std::isfinite(d.min) && std::isfinite(d.max) ? ""
                                                          : "needs a bounded distribution (uniform, "
                                                            "log_uniform, truncated_normal or choice)";
    case Domain::kChoice:
      return d.kind == DistributionKind::kChoice ? "" : "must be a choice: {choice: [...]}";
  }
  return "";
}

//! A `{choice: [...]}`: fault kinds among the spec's kinds, or gyros among the spec's gyros.
Status parse_choices(const YamlReader& yaml, const YAML::Node& v, const std::string& at,
                     const ParamInfo& info, const std::vector<FaultKind>& kinds,
                     const std::vector<int>& gyros, Distribution& d) {
  if (!v.IsSequence() || v.size() == 0) return yaml.error(v, at, "expected a non-empty list");
  d.kind = DistributionKind::kChoice;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string item = at + "[" + std::to_string(i) + "]";
    if (info.parameter == P::kFaultKind) {
      auto name = yaml.text(v[i], item);
      if (!name) return name.error();
      const auto kind = fault_kind_from_name(*name);
      const auto it = kind ? std::find(kinds.begin(), kinds.end(), *kind) : kinds.end();
      if (it == kinds.end()) return yaml.error(v[i], item, "'" + *name + "' is not one of the spec's kinds");
      d.choices.push_back(static_cast<double>(it - kinds.begin()));
    } else {
      auto g = yaml.integer(v[i], item, 1, kMaxGyros);
      if (!g) return g.error();
      if (std::find(gyros.begin(), gyros.end(), static_cast<int>(*g)) == gyros.end())
        return yaml.error(v[i], item,
                          "gyro " + std::to_string(*g) +
                              " is not in gyros (the gyros the "
                              "campaign checks)");
      d.choices.push_back(static_cast<double>(*g));
    }
  }
  d.min = *std::min_element(d.choices.begin(), d.choices.end());
  d.max = *std::max_element(d.choices.begin(), d.choices.end());
  return ok_status();
}

//! One distribution: `calibration`, {calibration: k}, {normal: [..]}, {uniform: [..]}, ...
Result<Distribution> parse_distribution(const YamlReader& yaml, const YAML::Node& node,
                                        const std::string& what, const ParamInfo& info,
                                        const std::vector<FaultKind>& kinds, const std::vector<int>& gyros) {
  Distribution d;
  if (node.IsScalar() && node.Scalar() == "calibration") {
    if (!info.calibration) return yaml.error(node, what, "has no calibration 1σ (give a distribution)");
    d.kind = DistributionKind::kCalibration;
    d.sigma = 1.0;
    return d;
  }
  if (!node.IsMap() || node.size() != 1)
    return yaml.error(
        node, what,
        info.domain == Domain::kChoice
            ? std::string("expected {choice: [...]}")
            : "expected one of {normal: [mean, sigma]}, {uniform: [min, max]}, {truncated_normal: "
              "[mean, sigma, min, max]}, {log_uniform: [min, max]}" +
                  std::string(info.calibration ? ", calibration, {calibration: k}" : ""));
  const std::string form = node.begin()->first.IsScalar() ? node.begin()->first.Scalar() : "?";
  const YAML::Node v = node.begin()->second;
  const std::string at = what + "." + form;
  if (form == "calibration" && info.calibration) {
    auto k = yaml.number(v, at);
    if (!k) return k.error();
    if (*k <= 0.0) return yaml.error(v, at, "the multiple of the 1σ must be positive");
    d.kind = DistributionKind::kCalibration;
    d.sigma = *k;
  } else if (form == "normal") {
    auto n = numbers_of(yaml, v, at, 2, "[mean, sigma]");
    if (!n) return n.error();
    if ((*n)[1] <= 0.0) return yaml.error(v, at, "sigma must be positive");
    d.kind = DistributionKind::kNormal;
    d.mean = (*n)[0];
    d.sigma = (*n)[1];
  } else if (form == "uniform" || form == "log_uniform") {
    auto n = numbers_of(yaml, v, at, 2, "[min, max]");
    if (!n) return n.error();
    if (!((*n)[0] < (*n)[1])) return yaml.error(v, at, "min must be below max");
    if (form == "log_uniform" && (*n)[0] <= 0.0) return yaml.error(v, at, "min must be positive");
    d.kind = form == "uniform" ? DistributionKind::kUniform : DistributionKind::kLogUniform;
    d.min = (*n)[0];
    d.max = (*n)[1];
  } else if (form == "truncated_normal") {
    auto n = numbers_of(yaml, v, at, 4, "[mean, sigma, min, max]");
    if (!n) return n.error();
    if ((*n)[1] <= 0.0) return yaml.error(v, at, "sigma must be positive");
    if (!((*n)[2] < (*n)[3])) return yaml.error(v, at, "min must be below max");
    // The mass of [min, max] must not vanish in double precision (a support 40σ from the mean).
    if (std::max((*n)[2] - (*n)[0], (*n)[0] - (*n)[3]) > 30.0 * (*n)[1])
      return yaml.error(v, at, "[min, max] lies more than 30 sigma from the mean");
    d.kind = DistributionKind::kTruncatedNormal;
    d.mean = (*n)[0];
    d.sigma = (*n)[1];
    d.min = (*n)[2];
    d.max = (*n)[3];
  } else if (form == "choice" && info.domain == Domain::kChoice) {
    if (Status st = parse_choices(yaml, v, at, info, kinds, gyros, d); !st) return st.error();
  } else {
    return yaml.error(node.begin()->first, what, "'" + form + "' is not a distribution for " + info.name);
  }
  if (std::string problem = domain_problem(info.domain, d); !problem.empty())
    return yaml.error(node, what, problem);
  return d;
}

//! Φ(x), the standard normal CDF.
double normal_cdf(double x) {
  return 0.5 * std::erfc(-x / std::sqrt(2.0));
}

//! A standard normal truncated to [a, b] by inversion (one uniform, so one engine call per draw). Drawn
//! in the lower tail (mirrored when a > 0), where Φ keeps its relative precision.
double truncated_standard_normal(Rng& rng, double a, double b) {
  if (a > 0.0) return -truncated_standard_normal(rng, -b, -a);
  const double fa = normal_cdf(a);
  const double target = fa + rng.uniform() * (normal_cdf(b) - fa);
  double lo = a;
  double hi = b;
  for (int i = 0; i < 200 && lo < hi; ++i) {
    const double mid = lo + 0.5 * (hi - lo);
    if (mid <= lo || mid >= hi) break;
    (normal_cdf(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

//! One draw; `one_sigma` is the calibration's 1σ of this component (kCalibration only).
double draw(const Distribution& d, Rng& rng, double one_sigma) {
  switch (d.kind) {
    case DistributionKind::kNormal:
      return d.mean + d.sigma * rng.normal();
    case DistributionKind::kUniform:
      return d.min + (d.max - d.min) * rng.uniform();
    case DistributionKind::kTruncatedNormal:
      return d.mean +
             d.sigma * truncated_standard_normal(rng, (d.min - d.mean) / d.sigma, (d.max - d.mean) / d.sigma);
    case DistributionKind::kLogUniform:
      return std::exp(std::log(d.min) + (std::log(d.max) - std::log(d.min)) * rng.uniform());
    case DistributionKind::kCalibration:
      return d.sigma * one_sigma * rng.normal();
    case DistributionKind::kChoice: {
      const auto i = static_cast<std::size_t>(rng.uniform() * static_cast<double>(d.choices.size()));
      return d.choices[std::min(i, d.choices.size() - 1)];
    }
  }
  return 0.0;
}

//! The calibration's 1σ of component `c` (0..2 for the axis, else 0) of gyro `g` for parameter p.
double calibration_sigma(P p, const GyroCalibration& g, int c) {
  if (!g.sigma) return 0.0;
  switch (p) {
    case P::kScaleFactorPpm:
      return g.sigma->scale_factor_V_per_dps / std::abs(g.scale_factor_V_per_dps) * 1e6;
    case P::kBiasV:
      return g.sigma->bias_V;
    case P::kAxis:
      return g.sigma->axis[c];
    default:
      return 0.0;
  }
}

//! The seed of parameter p's engine in run `run`.
std::uint64_t dispersion_seed(std::uint64_t seed, std::uint64_t run, P p) {
  return splitmix64(splitmix64(splitmix64(seed) ^ run) ^ ((static_cast<std::uint64_t>(p) + 1) << 40));
}

void scale_noise(std::optional<double>& term, double factor) {
  if (term) *term *= factor;
}

}  // namespace

std::string dispersion_parameter_name(DispersedParameter p) {
  return info_of(p).name;
}

Result<DispersionSpec> parse_dispersions(const YamlReader& yaml, const YAML::Node& node,
                                         const std::vector<FaultKind>& kinds, const std::vector<int>& gyros) {
  DispersionSpec spec;
  if (!node.IsMap()) return yaml.error(node, "dispersions", "expected a mapping (seed and parameters)");
  if (!node["seed"]) return yaml.error(node, "dispersions.seed", "missing (the draws are a function of it)");
  for (const auto& kv : node) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
    const std::string what = "dispersions." + key;
    if (key == "seed") {
      auto seed = yaml.unsigned_integer(kv.second, what);
      if (!seed) return seed.error();
      spec.seed = *seed;
      continue;
    }
    const ParamInfo* info = nullptr;
    for (const ParamInfo& i : kParams) {
      if (key == i.name) info = &i;
    }
    if (!info)
      return yaml.error(kv.first, what, "unknown parameter (allowed: seed, " + allowed_names() + ")");
    auto d = parse_distribution(yaml, kv.second, what, *info, kinds, gyros);
    if (!d) return d.error();
    spec.parameters.push_back({info->parameter, *d});
  }
  if (spec.parameters.empty()) return yaml.error(node, "dispersions", "no parameter to disperse");
  return spec;
}

namespace {

//! [deg/s²] the largest true rate ramp a run may draw: 3.6 deg/s after an hour, beyond any working gyro.
constexpr double kMaxRateRamp_dps2 = 1e-3;

//! The warm-up each corner of the thermal draws' supports gives `sc` is a valid scenario's (its biases within
//! kMaxThermalBias_dps, its temperatures in range), and it has a transient to give.
Status check_thermal_corners(const DispersionSpec& spec, const Scenario& sc) {
  std::optional<std::pair<double, double>> c;  // the coefficients' support, when drawn
  std::pair<double, double> start{sc.thermal.start_C, sc.thermal.start_C};
  for (const Dispersion& d : spec.parameters) {
    if (d.parameter == P::kThermalBiasDpsPerK) c = {d.distribution.min, d.distribution.max};
    if (d.parameter == P::kThermalStartC) start = {d.distribution.min, d.distribution.max};
  }
  if (!c && !sc.thermal.active())
    return bad_input(
        "a warm-up needs its coefficients: disperse thermal.bias_dps_per_K too, or give the "
        "scenario a thermal: section");
  const double cal_C = std::isnan(sc.thermal.calibrated_at_C) ? sc.thermal.end_C : sc.thermal.calibrated_at_C;
  if (start.first == cal_C && start.second == cal_C && sc.thermal.end_C == cal_C)
    return bad_input("no warm-up to give: the unit starts and settles at its calibration's " +
                     number_text(cal_C) + " degC; disperse thermal.start_C too, or give the scenario a " +
                     "thermal: section with start_C");
  for (const double ci : {c ? c->first : 0.0, c ? c->second : 0.0}) {
    for (const double t0 : {start.first, start.second}) {
      Scenario corner = sc;
      if (c) corner.thermal.bias_dps_per_K.assign(static_cast<std::size_t>(sc.unit.gyro_count()), ci);
      corner.thermal.start_C = t0;
      if (Status st = validate_scenario(corner); !st) return st;
    }
  }
  return ok_status();
}

}  // namespace

Status check_dispersions(const YamlReader& yaml, const YAML::Node& node, const DispersionSpec& spec,
                         const Scenario& sc, const std::string& name, bool closed_loop,
                         const std::vector<double>& onsets_s, const KindSizes& sizes) {
  for (const Dispersion& d : spec.parameters) {
    const std::string key = dispersion_parameter_name(d.parameter);
    const YAML::Node at = node[key];
    const std::string what = "dispersions." + key;
    const Distribution& dist = d.distribution;
    const bool spacecraft = d.parameter >= P::kInertiaPercent && d.parameter <= P::kDisturbancePeriodicNm;
    if (spacecraft && !closed_loop) return yaml.error(at, what, "applies to a closed-loop campaign only");
    if (d.parameter == P::kJitterS && closed_loop)
      return yaml.error(at, what, "applies to an open-loop campaign only (no jitter in closed loop)");
    const bool reference =
        d.parameter >= P::kReferenceNoiseArcsec && d.parameter <= P::kReferenceDropProbability;
    if (reference && sc.reference.rate_hz <= 0.0)
      return yaml.error(at, what, name + " has no attitude reference to disperse");
    if (dist.kind == DistributionKind::kCalibration) {
      for (const GyroCalibration& g : sc.unit.gyros) {
        if (!g.sigma)
          return yaml.error(
              at, what, "gyro " + std::to_string(g.id) + " of " + name + " has no calibration 1σ (sigma:)");
      }
    }
    // Sample times within ± jitter of the nominal ones stay in order only below half a period: beyond
    // it every run would be an error row.
    if (d.parameter == P::kJitterS && !(dist.max < 0.5 / sc.rate_hz))
      return yaml.error(at, what,
                        "jitter up to " + number_text(dist.max) + " s reaches half the sampling period (" +
                            number_text(0.5 / sc.rate_hz) + " s) of " + name +
                            ": give a distribution bounded below it");
    if (d.parameter == P::kFaultOnsetS) {
      const auto [lo, hi] = std::minmax_element(onsets_s.begin(), onsets_s.end());
      if (*lo + dist.min < 0.0 || *hi + dist.max >= sc.duration_s)
        return yaml.error(at, what,
                          "onsets from " + number_text(*lo + dist.min) + " to " +
                              number_text(*hi + dist.max) + " s do not all lie in [0, " +
                              number_text(sc.duration_s) + ") s of " + name);
    }
    if (d.parameter == P::kThermalBiasDpsPerK || d.parameter == P::kThermalStartC) {
      if (Status st = check_thermal_corners(spec, sc); !st) return yaml.error(at, what, st.error().message);
    }
    if (d.parameter == P::kRateRampDps2 && !(dist.min >= 0.0 && dist.max <= kMaxRateRamp_dps2))
      return yaml.error(at, what,
                        "rate ramps from " + number_text(dist.min) + " to " + number_text(dist.max) +
                            " deg/s^2: give a distribution within [0, " + number_text(kMaxRateRamp_dps2) +
                            "] (R is a magnitude, as in a calibration's noise: section)");
    if (d.parameter == P::kFaultSizeFactor) {
      for (const auto& [kind, values] : sizes) {
        for (double size : values) {
          for (double factor : {dist.min, dist.max}) {
            if (Status st = check_fault_size(kind, size * factor); !st)
              return yaml.error(at, what,
                                "size " + number_text(size) + " × " + number_text(factor) + " of kind " +
                                    std::string(fault_kind_name(kind)) + ": " + st.error().message);
          }
        }
      }
    }
  }
  return ok_status();
}

DispersionDraws draw_dispersions(const DispersionSpec& spec, std::uint64_t run, const Calibration& nominal) {
  DispersionDraws out;
  for (const Dispersion& d : spec.parameters) {
    Rng rng(dispersion_seed(spec.seed, run, d.parameter));
    std::vector<double> values;
    switch (info_of(d.parameter).shape) {
      case Shape::kPerGyro:
        for (const GyroCalibration& g : nominal.gyros)
          values.push_back(draw(d.distribution, rng, calibration_sigma(d.parameter, g, 0)));
        break;
      case Shape::kPerGyroXyz:
        for (const GyroCalibration& g : nominal.gyros) {
          for (int c = 0; c < 3; ++c)
            values.push_back(draw(d.distribution, rng, calibration_sigma(d.parameter, g, c)));
        }
        break;
      case Shape::kXyz:
        for (int c = 0; c < 3; ++c) values.push_back(draw(d.distribution, rng, 0.0));
        break;
      case Shape::kScalar:
        values.push_back(draw(d.distribution, rng, 0.0));
        break;
    }
    out.push_back(std::move(values));
  }
  return out;
}

namespace {

void disperse_unit(Calibration& unit, P p, const std::vector<double>& v) {
  for (std::size_t i = 0; i < unit.gyros.size(); ++i) {
    GyroCalibration& g = unit.gyros[i];
    switch (p) {
      case P::kScaleFactorPpm:
        g.scale_factor_V_per_dps *= 1.0 + v[i] * 1e-6;
        break;
      case P::kBiasV:
        g.bias_V += v[i];
        break;
      case P::kAxis:
        g.axis_B = (g.axis_B + Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2])).normalized();
        break;
      case P::kArwFactor:
        if (g.noise) scale_noise(g.noise->arw_dps_rtHz, v[i]);
        break;
      case P::kBiasInstabilityFactor:
        if (g.noise) scale_noise(g.noise->bias_instability_dps, v[i]);
        break;
      case P::kRateRandomWalkFactor:
        if (g.noise) scale_noise(g.noise->rate_random_walk_dps_per_rts, v[i]);
        break;
      case P::kQuantizationFactor:
        if (g.noise) scale_noise(g.noise->quantization_deg, v[i]);
        break;
      case P::kRateRampDps2:
        if (!g.noise) g.noise.emplace();
        g.noise->rate_ramp_dps_per_s = v[i];
        break;
      default:
        break;
    }
  }
}

void disperse_spacecraft(ClosedLoopSpec& cl, P p, const std::vector<double>& v) {
  const Eigen::Vector3d x(v[0], v[1], v[2]);
  switch (p) {
    case P::kInertiaPercent: {
      const Eigen::Matrix3d s = (Eigen::Vector3d::Ones() + x / 100.0).cwiseSqrt().asDiagonal();
      cl.inertia_kg_m2 = s * cl.inertia_kg_m2 * s;
      break;
    }
    case P::kInertiaAxesDeg: {
      const Eigen::Vector3d r = x * kDegToRad;
      const Eigen::Matrix3d rot = r.norm() > 0.0
                                      ? Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix()
                                      : Eigen::Matrix3d::Identity();
      cl.inertia_kg_m2 = rot * cl.inertia_kg_m2 * rot.transpose();
      break;
    }
    case P::kDisturbanceConstantNm:
      cl.disturbance.constant_Nm += x;
      break;
    case P::kDisturbancePeriodicNm:
      cl.disturbance.periodic_Nm += x;
      break;
    default:
      break;
  }
}

}  // namespace

Scenario dispersed_scenario(const Scenario& nominal, const DispersionSpec& spec,
                            const DispersionDraws& draws) {
  Scenario sc = nominal;
  for (std::size_t i = 0; i < spec.parameters.size() && i < draws.size(); ++i) {
    const P p = spec.parameters[i].parameter;
    const std::vector<double>& v = draws[i];
    const Shape shape = info_of(p).shape;
    if (p == P::kThermalBiasDpsPerK) {
      sc.thermal.bias_dps_per_K = v;
    } else if (p == P::kThermalStartC) {
      sc.thermal.start_C = v[0];
    } else if (shape == Shape::kPerGyro || shape == Shape::kPerGyroXyz) {
      disperse_unit(sc.unit, p, v);
    } else if (shape == Shape::kXyz) {
      if (sc.closed_loop) disperse_spacecraft(*sc.closed_loop, p, v);
    } else if (p == P::kReferenceNoiseArcsec) {
      sc.reference.noise_arcsec = v[0];
    } else if (p == P::kReferenceBiasArcsec) {
      sc.reference.bias_arcsec = v[0];
      sc.reference.bias_at_s = 0.0;
      sc.reference.bias_ramp_s = 0.0;
    } else if (p == P::kReferenceLatencyS) {
      sc.reference.latency_s = v[0];
    } else if (p == P::kReferenceDropProbability) {
      sc.reference.drop_probability = v[0];
    } else if (p == P::kDropProbability) {
      sc.drop_probability = v[0];
    } else if (p == P::kJitterS) {
      sc.jitter_s = v[0];
    }
  }
  return sc;
}

FaultSpec dispersed_fault(const FaultSpec& fault, const DispersionSpec& spec, const DispersionDraws& draws,
                          const std::vector<FaultKind>& kinds, const KindSizes& sizes) {
  FaultSpec f = fault;
  for (std::size_t i = 0; i < spec.parameters.size() && i < draws.size(); ++i) {
    if (spec.parameters[i].parameter != P::kFaultKind) continue;
    f.kind = kinds[static_cast<std::size_t>(draws[i][0])];
    f.size = 0.0;
    for (const auto& [kind, values] : sizes) {
      if (kind == f.kind) f.size = values.front();
    }
  }
  for (std::size_t i = 0; i < spec.parameters.size() && i < draws.size(); ++i) {
    const double v = draws[i][0];
    switch (spec.parameters[i].parameter) {
      case P::kFaultOnsetS:
        f.at_s += v;
        break;
      case P::kFaultSizeFactor:
        f.size *= v;
        break;
      case P::kFaultGyro:
        f.gyro = static_cast<int>(v);
        break;
      default:
        break;
    }
  }
  return f;
}

std::vector<std::string> dispersion_columns(const DispersionSpec& spec, int gyros) {
  std::vector<std::string> out;
  for (const Dispersion& d : spec.parameters) {
    const std::string name = dispersion_parameter_name(d.parameter);
    switch (info_of(d.parameter).shape) {
      case Shape::kPerGyro:
        for (int g = 1; g <= gyros; ++g) out.push_back(name + ".g" + std::to_string(g));
        break;
      case Shape::kPerGyroXyz:
        for (int g = 1; g <= gyros; ++g) {
          for (const char* c : {".x", ".y", ".z"}) out.push_back(name + ".g" + std::to_string(g) + c);
        }
        break;
      case Shape::kXyz:
        for (const char* c : {".x", ".y", ".z"}) out.push_back(name + c);
        break;
      case Shape::kScalar:
        out.push_back(name);
        break;
    }
  }
  return out;
}

std::vector<std::string> dispersion_fields(const DispersionSpec& spec, const DispersionDraws& draws,
                                           int gyros, const std::vector<FaultKind>& kinds) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
    const P p = spec.parameters[i].parameter;
    const Shape shape = info_of(p).shape;
    const std::vector<double> none;
    const std::vector<double>& v = i < draws.size() ? draws[i] : none;
    const std::size_t width = shape == Shape::kPerGyro      ? static_cast<std::size_t>(gyros)
                              : shape == Shape::kPerGyroXyz ? 3 * static_cast<std::size_t>(gyros)
                              : shape == Shape::kXyz        ? 3
                                                            : 1;
    for (std::size_t c = 0; c < width; ++c) {
      std::string field;
      if (c < v.size()) {
        if (p == P::kFaultKind) {
          field = std::string(fault_kind_name(kinds[static_cast<std::size_t>(v[c])]));
        } else {
          append_double(field, v[c]);
        }
      }
      out.push_back(field);  // empty: a gyro this run's unit does not have
    }
  }
  return out;
}

}  // namespace tetra::sim
