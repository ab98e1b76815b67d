#include "tetra/sim/campaign.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/yaml_reader.hpp"
#include "tetra/fdi/budget.hpp"
#include "tetra/fdi/detectors.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/pointing_report.hpp"
#include "text.hpp"

namespace tetra::sim {

namespace {

FaultSpec fault_of(FaultKind kind, int gyro, double onset_s, double size) {
  FaultSpec f;
  f.kind = kind;
  f.gyro = gyro;
  f.at_s = onset_s;
  f.size = size;
  return f;
}

//! A non-empty list under parent[key] (named `what` in messages), each element read by
//! `read(node, "what[i]")`; a value given twice is an error (it would repeat runs).
template <class T, class Read>
Result<std::vector<T>> list_of(const YamlReader& yaml, const YAML::Node& parent, const std::string& key,
                               const std::string& what, Read read) {
  const YAML::Node node = parent[key];
  if (!node) return yaml.error(parent, what, "missing");
  if (!node.IsSequence() || node.size() == 0) return yaml.error(node, what, "expected a non-empty list");
  std::vector<T> out;
  out.reserve(node.size());
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string item = what + "[" + std::to_string(i) + "]";
    Result<T> value = read(node[i], item);
    if (!value) return value.error();
    out.push_back(std::move(value.value()));
  }
  std::vector<std::size_t> order(out.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return out[a] < out[b]; });
  for (std::size_t i = 1; i < order.size(); ++i) {
    if (out[order[i]] == out[order[i - 1]])
      return yaml.error(node[order[i]], what + "[" + std::to_string(order[i]) + "]",
                        "the same value as " + what + "[" + std::to_string(order[i - 1]) +
                            "] (each value once: a repeat would run the same cases twice)");
  }
  return out;
}

//! `kinds:` and, for those taking a size, `sizes:` (a key for a kind not in `kinds`, or one that takes
//! no size, is an error: its sizes would never run).
Status parse_kinds_and_sizes(const YamlReader& yaml, const YAML::Node& root, CampaignSpec& spec) {
  auto kinds =
      list_of<std::string>(yaml, root, "kinds", "kinds",
                           [&](const YAML::Node& n, const std::string& w) { return yaml.text(n, w); });
  if (!kinds) return kinds.error();
  const YAML::Node sizes = root["sizes"];
  if (sizes && !sizes.IsMap()) return yaml.error(sizes, "sizes", "expected a mapping of kind: [sizes]");
  for (std::size_t i = 0; i < kinds->size(); ++i) {
    const auto kind = fault_kind_from_name((*kinds)[i]);
    if (!kind) return yaml.error(root["kinds"][i], "kinds", "'" + (*kinds)[i] + "' is not a fault kind");
    spec.kinds.push_back(*kind);
    if (!kind_takes_size(*kind)) continue;
    const std::string what = "sizes." + (*kinds)[i];
    if (!sizes || !sizes[(*kinds)[i]])
      return yaml.error(root["kinds"][i], what, "missing (kind " + (*kinds)[i] + " needs sizes)");
    auto values =
        list_of<double>(yaml, sizes, (*kinds)[i], what, [&](const YAML::Node& n, const std::string& w) {
          auto v = yaml.number(n, w);
          if (!v) return v;
          if (Status st = check_fault_size(*kind, *v); !st)
            return Result<double>(yaml.error(n, w, st.error().message));
          return v;
        });
    if (!values) return values.error();
    spec.sizes.emplace_back(*kind, *values);
  }
  if (!sizes) return ok_status();
  for (const auto& kv : sizes) {
    const std::string name = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
    const auto kind = fault_kind_from_name(name);
    if (!kind || !kind_takes_size(*kind))
      return yaml.error(kv.first, "sizes." + name,
                        kind ? "kind " + name + " takes no size" : "'" + name + "' is not a fault kind");
    if (std::find(spec.kinds.begin(), spec.kinds.end(), *kind) == spec.kinds.end())
      return yaml.error(kv.first, "sizes." + name,
                        "kind " + name + " is not in kinds (these sizes would never run)");
  }
  return ok_status();
}

//! `scenarios:` files (relative to the spec) or built-in names; closed loop needs closed_loop sections.
Status parse_scenarios(const YamlReader& yaml, const YAML::Node& root, const std::string& base_dir,
                       CampaignSpec& spec) {
  auto paths =
      list_of<std::string>(yaml, root, "scenarios", "scenarios",
                           [&](const YAML::Node& n, const std::string& w) { return yaml.text(n, w); });
  if (!paths) return paths.error();
  const std::vector<std::string> builtin = builtin_scenario_names();
  for (std::size_t i = 0; i < paths->size(); ++i) {
    std::filesystem::path path = (*paths)[i];
    const bool is_builtin =
        std::find(builtin.begin(), builtin.end(), (*paths)[i]) != builtin.end() && !path.has_extension();
    if (path.is_relative() && !is_builtin) path = std::filesystem::path(base_dir) / path;
    auto sc = is_builtin ? builtin_scenario((*paths)[i]) : read_scenario(path.string());
    const std::string what = "scenarios[" + std::to_string(i) + "]";
    if (!sc) return yaml.error(root["scenarios"][i], what, sc.error().message);
    if (spec.loop == CampaignLoop::kClosed && !sc->closed_loop)
      return yaml.error(root["scenarios"][i], what,
                        path.string() + " has no closed_loop section (or set loop: open)");
    spec.scenario_paths.push_back(path.string());
    spec.scenarios.push_back(std::move(sc.value()));
  }
  return ok_status();
}

//! `loop:`, `target:` and `domain:`.
Status parse_mode(const YamlReader& yaml, const YAML::Node& root, CampaignSpec& spec) {
  if (const YAML::Node loop = root["loop"]) {
    const auto text = yaml.text(loop, "loop");
    if (!text) return text.error();
    if (*text != "closed" && *text != "open") return yaml.error(loop, "loop", "must be closed or open");
    spec.loop = *text == "open" ? CampaignLoop::kOpen : CampaignLoop::kClosed;
  }
  if (const YAML::Node target = root["target"]) {
    const auto text = yaml.text(target, "target");
    if (!text) return text.error();
    if (*text != "in_process" && *text != "dds")
      return yaml.error(target, "target", "must be in_process or dds");
    spec.target = *text == "dds" ? CampaignTarget::kDds : CampaignTarget::kInProcess;
  }
  if (const YAML::Node domain = root["domain"]) {
    if (spec.target != CampaignTarget::kDds)
      return yaml.error(domain, "domain", "applies to target: dds only");
    const auto id = yaml.integer(domain, "domain", 0, 232);  // a DDS domain id
    if (!id) return id.error();
    spec.dds_domain = static_cast<int>(*id);
  }
  return ok_status();
}

//! `seeds: {first: F, count: C}`: the seeds F, F + 1, ..., F + C − 1 (a Monte Carlo campaign's runs).
Result<std::vector<std::uint64_t>> seed_range(const YamlReader& yaml, const YAML::Node& node) {
  if (Status st = yaml.check_keys(node, {"first", "count"}, "seeds"); !st) return st.error();
  if (!node["first"] || !node["count"]) return yaml.error(node, "seeds", "expected {first: F, count: C}");
  auto first = yaml.unsigned_integer(node["first"], "seeds.first");
  if (!first) return first.error();
  auto count = yaml.integer(node["count"], "seeds.count", 1, static_cast<std::int64_t>(kMaxCampaignRuns));
  if (!count) return count.error();
  if (*first > std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(*count - 1))
    return yaml.error(node["count"], "seeds.count", "the last seed would pass 2^64 - 1");
  std::vector<std::uint64_t> seeds(static_cast<std::size_t>(*count));
  for (std::size_t i = 0; i < seeds.size(); ++i) seeds[i] = *first + i;
  return seeds;
}

//! `requirements:` a list of "METRIC < BOUND at CONFIDENCE"; a kind named must be one the campaign runs.
Status parse_requirements(const YamlReader& yaml, const YAML::Node& root, CampaignSpec& spec) {
  const YAML::Node list = root["requirements"];
  if (!list) return ok_status();
  if (!list.IsSequence() || list.size() == 0)
    return yaml.error(list, "requirements", "expected a non-empty list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string what = "requirements[" + std::to_string(i) + "]";
    auto text = yaml.text(list[i], what);
    if (!text) return text.error();
    auto r = parse_requirement(*text);
    if (!r) return yaml.error(list[i], what, r.error().message);
    const auto kind = fault_kind_from_name(r->kind);
    if (r->kind == "none"
            ? !spec.fault_free
            : kind && std::find(spec.kinds.begin(), spec.kinds.end(), *kind) == spec.kinds.end())
      return yaml.error(
          list[i], what,
          "the campaign runs no " + r->kind + (r->kind == "none" ? " (fault_free: false)" : " fault"));
    spec.requirements.push_back(*r);
  }
  return ok_status();
}

//! `gyros:`, `onsets_s:`, `seeds:`, `duration_s:` and `fault_free:`.
Status parse_axes(const YamlReader& yaml, const YAML::Node& root, CampaignSpec& spec) {
  auto gyros = list_of<int>(yaml, root, "gyros", "gyros", [&](const YAML::Node& n, const std::string& w) {
    auto g = yaml.integer(n, w, 1, kMaxGyros);
    return g ? Result<int>(static_cast<int>(*g)) : Result<int>(g.error());
  });
  if (!gyros) return gyros.error();
  spec.gyros = *gyros;
  auto onsets =
      list_of<double>(yaml, root, "onsets_s", "onsets_s", [&](const YAML::Node& n, const std::string& w) {
        auto v = yaml.number(n, w);
        if (v && *v < 0.0) return Result<double>(yaml.error(n, w, "must not be negative"));
        return v;
      });
  if (!onsets) return onsets.error();
  spec.onsets_s = *onsets;
  if (root["seeds"].IsMap()) {
    auto seeds = seed_range(yaml, root["seeds"]);
    if (!seeds) return seeds.error();
    spec.seeds = *seeds;
  } else {
    auto seeds = list_of<std::uint64_t>(
        yaml, root, "seeds", "seeds",
        [&](const YAML::Node& n, const std::string& w) { return yaml.unsigned_integer(n, w); });
    if (!seeds) return seeds.error();
    spec.seeds = *seeds;
  }
  if (root["duration_s"]) {
    auto d = yaml.number(root["duration_s"], "duration_s");
    if (!d) return d.error();
    if (*d <= 0.0) return yaml.error(root["duration_s"], "duration_s", "must be positive");
    spec.duration_s = *d;
  }
  if (root["fault_free"]) {
    auto b = yaml.boolean(root["fault_free"], "fault_free");
    if (!b) return b.error();
    spec.fault_free = *b;
  }
  return ok_status();
}

Result<CampaignSpec> parse_spec(const YAML::Node& root, const YamlReader& yaml, const std::string& base_dir) {
  if (Status st = yaml.check_keys(
          root,
          {"scenarios", "kinds", "gyros", "onsets_s", "sizes", "seeds", "duration_s", "fault_free",
           "pipeline", "loop", "target", "domain", "dispersions", "requirements"},
          "");
      !st)
    return st.error();
  CampaignSpec spec;
  if (Status st = parse_mode(yaml, root, spec); !st) return st.error();
  if (Status st = parse_scenarios(yaml, root, base_dir, spec); !st) return st.error();
  if (Status st = parse_kinds_and_sizes(yaml, root, spec); !st) return st.error();
  if (Status st = parse_axes(yaml, root, spec); !st) return st.error();
  if (Status st = parse_requirements(yaml, root, spec); !st) return st.error();
  if (root["dispersions"]) {
    auto dispersions = parse_dispersions(yaml, root["dispersions"], spec.kinds, spec.gyros);
    if (!dispersions) return dispersions.error();
    spec.dispersions = *dispersions;
  }
  auto pipeline = fdi::pipeline_config_from_yaml(root["pipeline"], yaml.source());
  if (!pipeline) return pipeline.error();
  spec.pipeline = pipeline.value();
  spec.pipeline_yaml = root["pipeline"] ? YAML::Dump(root["pipeline"]) : "{}";
  return spec;
}

//! Every case can run, checked once per axis value rather than per case: each scenario as the campaign
//! runs it (its duration); each onset before the end of each scenario; each kind on each gyro of each
//! scenario (a noise fault needs the gyro's white noise). A unit the fusion pipeline cannot run (gyro
//! axes coplanar) is not refused here: its runs are error rows naming the run and why.
Status check_cases(const CampaignSpec& spec, const YAML::Node& root, const YamlReader& yaml) {
  for (std::size_t s = 0; s < spec.scenarios.size(); ++s) {
    const std::string name = "scenarios[" + std::to_string(s) + "] (" + spec.scenarios[s].name + ")";
    const YAML::Node at = root["scenarios"][s];
    CampaignCase fault_free;
    fault_free.scenario = s;
    const Scenario sc = campaign_scenario(spec, fault_free);
    if (Status st = validate_scenario(sc); !st) {
      const YAML::Node key = spec.duration_s ? root["duration_s"] : at;
      return yaml.error(key, spec.duration_s ? "duration_s" : name,
                        (spec.duration_s ? "with " + name + ": " : std::string()) + st.error().message);
    }
    if (!spec.dispersions.empty()) {
      if (Status st = check_dispersions(yaml, root["dispersions"], spec.dispersions, sc, name,
                                        spec.loop == CampaignLoop::kClosed, spec.onsets_s, spec.sizes);
          !st)
        return st;
    }
    for (std::size_t g = 0; g < spec.gyros.size(); ++g) {
      if (spec.gyros[g] > sc.unit.gyro_count())
        return yaml.error(root["gyros"][g], "gyros[" + std::to_string(g) + "]",
                          "gyro " + std::to_string(spec.gyros[g]) + " does not exist in " + name + " (" +
                              std::to_string(sc.unit.gyro_count()) + " gyros)");
    }
    for (std::size_t o = 0; o < spec.onsets_s.size(); ++o) {
      if (spec.onsets_s[o] >= sc.duration_s)
        return yaml.error(root["onsets_s"][o], "onsets_s[" + std::to_string(o) + "]",
                          number_text(spec.onsets_s[o]) + " s is at or after the end of " + name + " (" +
                              number_text(sc.duration_s) + " s" + (spec.duration_s ? ", duration_s" : "") +
                              ")");
    }
    for (std::size_t k = 0; k < spec.kinds.size(); ++k) {
      for (int gyro : spec.gyros) {
        CampaignCase c = fault_free;
        double size = 0.0;
        for (const auto& [kind, values] : spec.sizes) {
          if (kind == spec.kinds[k]) size = values.front();
        }
        c.fault = fault_of(spec.kinds[k], gyro, spec.onsets_s.front(), size);
        Scenario with_fault = sc;
        with_fault.faults = {*c.fault};
        if (Status st = validate_scenario(with_fault); !st)
          return yaml.error(
              root["kinds"][k], "kinds[" + std::to_string(k) + "]",
              "cannot run on gyro " + std::to_string(gyro) + " of " + name + ": " + st.error().message);
      }
    }
  }
  return ok_status();
}

}  // namespace

Result<CampaignSpec> read_campaign_spec(const std::string& path) {
  auto text = read_input(path, kMaxYamlBytes);
  if (!text) return text.error();
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parse_campaign_spec(*text, path, parent.empty() ? "." : parent.string());
}

Result<CampaignSpec> parse_campaign_spec(const std::string& yaml_text, const std::string& source,
                                         const std::string& base_dir) {
  const std::string& path = source;
  const YamlReader yaml{path};
  try {
    auto loaded = yaml.load(yaml_text);
    if (!loaded) return loaded.error();
    const YAML::Node root = *loaded;
    if (!root || !root.IsMap()) return bad_input(path + ": expected a mapping (docs/campaign.md)");
    auto spec = parse_spec(root, yaml, base_dir);
    if (!spec) return spec.error();
    // The size first: a small spec may describe an enormous matrix, refused before any other work.
    if (auto runs = campaign_run_count(*spec); !runs) return bad_input(path + ": " + runs.error().message);
    if (Status st = check_cases(*spec, root, yaml); !st) return st.error();
    return spec;
  } catch (const YAML::Exception& e) {
    return yaml.error(e, "");
  }
}

namespace {

//! a·b, or nullopt above kMaxCampaignRuns (no overflow: the factors are checked before the product).
std::optional<std::size_t> bounded_product(std::size_t a, std::size_t b) {
  if (a != 0 && b > kMaxCampaignRuns / a) return std::nullopt;
  return a * b;
}

//! The sizes of `kind` (one size, 0, for a kind that takes none).
std::size_t size_count(const CampaignSpec& spec, FaultKind kind) {
  for (const auto& [k, values] : spec.sizes) {
    if (k == kind) return values.size();
  }
  return 1;
}

//! Case `index` of the matrix, before its dispersions.
CampaignCase matrix_case(const CampaignSpec& spec, std::size_t index);

//! Runs of one scenario, or nullopt above kMaxCampaignRuns.
std::optional<std::size_t> runs_per_scenario(const CampaignSpec& spec) {
  std::optional<std::size_t> total = spec.fault_free ? spec.seeds.size() : 0;
  for (FaultKind kind : spec.kinds) {
    std::optional<std::size_t> n = spec.gyros.size();
    for (std::size_t factor : {spec.onsets_s.size(), size_count(spec, kind), spec.seeds.size()}) {
      if (n) n = bounded_product(*n, factor);
    }
    if (!n || !total || *total + *n > kMaxCampaignRuns) return std::nullopt;
    *total += *n;
  }
  return total;
}

}  // namespace

Result<std::size_t> campaign_run_count(const CampaignSpec& spec) {
  std::optional<std::size_t> runs = runs_per_scenario(spec);
  if (runs) runs = bounded_product(*runs, spec.scenarios.size());
  if (runs && *runs > 0) return *runs;
  std::size_t max_sizes = 0;
  for (FaultKind kind : spec.kinds) max_sizes = std::max(max_sizes, size_count(spec, kind));
  // The exact count, in floating point where it would overflow (it is only printed).
  double count = spec.fault_free ? static_cast<double>(spec.seeds.size()) : 0.0;
  for (FaultKind kind : spec.kinds) {
    count += static_cast<double>(spec.gyros.size()) * static_cast<double>(spec.onsets_s.size()) *
             static_cast<double>(size_count(spec, kind)) * static_cast<double>(spec.seeds.size());
  }
  count *= static_cast<double>(spec.scenarios.size());
  const std::string lists =
      "scenarios " + std::to_string(spec.scenarios.size()) + ", kinds " + std::to_string(spec.kinds.size()) +
      ", gyros " + std::to_string(spec.gyros.size()) + ", onsets_s " + std::to_string(spec.onsets_s.size()) +
      ", sizes up to " + std::to_string(max_sizes) + " a kind, seeds " + std::to_string(spec.seeds.size());
  if (!runs) {
    char text[32];
    std::snprintf(text, sizeof text, count < 1e15 ? "%.0f" : "%.3g", count);  // exact, or 3 digits
    return bad_input("the matrix has " + std::string(text) + " runs (" + lists + "), more than " +
                     std::to_string(kMaxCampaignRuns) + ": split the campaign (docs/campaign.md)");
  }
  return bad_input("the matrix has no run (" + lists + ")");
}

CampaignCase campaign_case(const CampaignSpec& spec, std::size_t index) {
  CampaignCase c = matrix_case(spec, index);
  if (spec.dispersions.empty()) return c;
  c.draws = draw_dispersions(spec.dispersions, index, spec.scenarios[c.scenario].unit);
  if (c.fault) c.fault = dispersed_fault(*c.fault, spec.dispersions, c.draws, spec.kinds, spec.sizes);
  return c;
}

int CampaignSpec::max_gyro_count() const {
  int n = 0;
  for (const Scenario& sc : scenarios) n = std::max(n, sc.unit.gyro_count());
  return n;
}

namespace {

CampaignCase matrix_case(const CampaignSpec& spec, std::size_t index) {
  const std::size_t per_scenario = *runs_per_scenario(spec);
  CampaignCase c;
  c.index = index;
  c.scenario = index / per_scenario;
  std::size_t r = index % per_scenario;
  const std::size_t seeds = spec.seeds.size();
  if (spec.fault_free) {
    if (r < seeds) {
      c.seed = spec.seeds[r];
      return c;
    }
    r -= seeds;
  }
  for (FaultKind kind : spec.kinds) {
    const std::size_t sizes = size_count(spec, kind);
    const std::size_t block = spec.gyros.size() * spec.onsets_s.size() * sizes * seeds;
    if (r >= block) {
      r -= block;
      continue;
    }
    // Mixed radix, the seed fastest: gyro, onset, size, seed.
    c.seed = spec.seeds[r % seeds];
    r /= seeds;
    const std::size_t z = r % sizes;
    r /= sizes;
    const std::size_t o = r % spec.onsets_s.size();
    const std::size_t g = r / spec.onsets_s.size();
    double size = 0.0;
    for (const auto& [k, values] : spec.sizes) {
      if (k == kind) size = values[z];
    }
    c.fault = fault_of(kind, spec.gyros[g], spec.onsets_s[o], size);
    return c;
  }
  return c;  // not reached for index < campaign_run_count(spec)
}

}  // namespace

std::optional<double> cusum_theory_delay_s(const Calibration& unit, const fdi::PipelineConfig& config,
                                           double rate_hz, int gyro, double size_dps) {
  const int n = unit.gyro_count();
  const double dt_s = 1.0 / rate_hz;
  Eigen::MatrixX3d axes(n, 3);
  Eigen::VectorXd sigma_dps(n);
  for (int i = 0; i < n; ++i) {
    const GyroCalibration& g = unit.gyros[static_cast<std::size_t>(i)];
    axes.row(i) = g.axis_B.transpose();
    const double arw =
        g.noise && g.noise->arw_dps_rtHz ? *g.noise->arw_dps_rtHz : config.default_arw_dps_rtHz;
    sigma_dps[i] = arw / std::sqrt(dt_s);
  }
  auto geometry = GyroGeometry::create(axes, sigma_dps);
  if (!geometry) return std::nullopt;
  auto parity = geometry->parity_matrix(geometry->all());
  if (!parity || parity->rows() != 1) return std::nullopt;  // the one-dimensional CUSUM (N = 4)
  // Sensitivity of the normalized parity to a unit step on each gyro: w_i = P_i / sqrt(Σ P_j² σ_j²).
  const Eigen::VectorXd p = parity->row(0).transpose();
  const double norm = std::sqrt((p.array().square() * sigma_dps.array().square()).sum());
  const Eigen::VectorXd w = p.cwiseAbs() / norm;
  const double k = 0.5 * config.cusum_min_fault_dps * w.minCoeff();
  const double h = fdi::cusum_threshold(k, fdi::cusum_arl0_epochs(config));
  const double delta = std::abs(size_dps) * w[gyro - 1];
  if (delta <= k) return std::nullopt;
  return fdi::cusum_arl(delta, k, h) * dt_s;
}

}  // namespace tetra::sim
