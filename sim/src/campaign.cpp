#include "tetra/sim/campaign.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/yaml_reader.hpp"
#include "tetra/fdi/detectors.hpp"
#include "tetra/sim/closed_loop_run.hpp"
#include "tetra/sim/pointing_report.hpp"
#include "text.hpp"

namespace tetra::sim {

namespace {

template <class T>
Result<std::vector<T>> list_of(const YamlReader& yaml, const YAML::Node& root, const std::string& key) {
  const YAML::Node node = root[key];
  if (!node) return yaml.error(root, key, "missing");
  if (!node.IsSequence() || node.size() == 0) return yaml.error(node, key, "expected a non-empty list");
  std::vector<T> out;
  for (std::size_t i = 0; i < node.size(); ++i) out.push_back(node[i].as<T>());
  return out;
}

Status parse_kinds_and_sizes(const YamlReader& yaml, const YAML::Node& root, CampaignSpec& spec) {
  auto kinds = list_of<std::string>(yaml, root, "kinds");
  if (!kinds) return kinds.error();
  const YAML::Node sizes = root["sizes"];
  for (std::size_t i = 0; i < kinds->size(); ++i) {
    const auto kind = fault_kind_from_name((*kinds)[i]);
    if (!kind) return yaml.error(root["kinds"][i], "kinds", "'" + (*kinds)[i] + "' is not a fault kind");
    spec.kinds.push_back(*kind);
    if (!kind_takes_size(*kind)) continue;
    if (!sizes || !sizes[(*kinds)[i]])
      return yaml.error(root["kinds"][i], "sizes." + (*kinds)[i],
                        "missing (kind " + (*kinds)[i] + " needs sizes)");
    auto values = list_of<double>(yaml, sizes, (*kinds)[i]);
    if (!values) return values.error();
    spec.sizes.emplace_back(*kind, *values);
  }
  return ok_status();
}

//! `scenarios:` files (relative to the spec) or built-in names; closed loop needs closed_loop sections.
Status parse_scenarios(const YamlReader& yaml, const YAML::Node& root, const std::string& base_dir,
                       CampaignSpec& spec) {
  auto paths = list_of<std::string>(yaml, root, "scenarios");
  if (!paths) return paths.error();
  const std::vector<std::string> builtin = builtin_scenario_names();
  for (std::size_t i = 0; i < paths->size(); ++i) {
    std::filesystem::path path = (*paths)[i];
    const bool is_builtin =
        std::find(builtin.begin(), builtin.end(), (*paths)[i]) != builtin.end() && !path.has_extension();
    if (path.is_relative() && !is_builtin) path = std::filesystem::path(base_dir) / path;
    auto sc = is_builtin ? builtin_scenario((*paths)[i]) : read_scenario(path.string());
    if (!sc) return yaml.error(root["scenarios"][i], "scenarios", sc.error().message);
    if (spec.loop == CampaignLoop::kClosed && !sc->closed_loop)
      return yaml.error(root["scenarios"][i], "scenarios",
                        path.string() + " has no closed_loop section (or set loop: open)");
    spec.scenario_paths.push_back(path.string());
    spec.scenarios.push_back(std::move(sc.value()));
  }
  return ok_status();
}

//! `loop:`, `target:` and `domain:`.
Status parse_mode(const YamlReader& yaml, const YAML::Node& root, CampaignSpec& spec) {
  if (const YAML::Node loop = root["loop"]) {
    const auto text = loop.as<std::string>();
    if (text != "closed" && text != "open") return yaml.error(loop, "loop", "must be closed or open");
    spec.loop = text == "open" ? CampaignLoop::kOpen : CampaignLoop::kClosed;
  }
  if (const YAML::Node target = root["target"]) {
    const auto text = target.as<std::string>();
    if (text != "in_process" && text != "dds")
      return yaml.error(target, "target", "must be in_process or dds");
    spec.target = text == "dds" ? CampaignTarget::kDds : CampaignTarget::kInProcess;
  }
  if (const YAML::Node domain = root["domain"]) {
    if (spec.target != CampaignTarget::kDds)
      return yaml.error(domain, "domain", "applies to target: dds only");
    const int id = domain.as<int>();
    if (id < 0 || id > 232) return yaml.error(domain, "domain", "must be a DDS domain id in 0..232");
    spec.dds_domain = id;
  }
  return ok_status();
}

Result<CampaignSpec> parse_spec(const YAML::Node& root, const YamlReader& yaml, const std::string& base_dir) {
  if (Status st = yaml.check_keys(root,
                                  {"scenarios", "kinds", "gyros", "onsets_s", "sizes", "seeds", "duration_s",
                                   "fault_free", "pipeline", "loop", "target", "domain"},
                                  "");
      !st)
    return st.error();
  CampaignSpec spec;
  if (Status st = parse_mode(yaml, root, spec); !st) return st.error();
  if (Status st = parse_scenarios(yaml, root, base_dir, spec); !st) return st.error();
  if (Status st = parse_kinds_and_sizes(yaml, root, spec); !st) return st.error();
  auto gyros = list_of<int>(yaml, root, "gyros");
  if (!gyros) return gyros.error();
  spec.gyros = *gyros;
  auto onsets = list_of<double>(yaml, root, "onsets_s");
  if (!onsets) return onsets.error();
  spec.onsets_s = *onsets;
  auto seeds = list_of<std::uint64_t>(yaml, root, "seeds");
  if (!seeds) return seeds.error();
  spec.seeds = *seeds;
  if (root["duration_s"]) {
    auto d = yaml.number(root["duration_s"], "duration_s");
    if (!d) return d.error();
    if (*d <= 0.0) return yaml.error(root["duration_s"], "duration_s", "must be positive");
    spec.duration_s = *d;
  }
  if (root["fault_free"]) spec.fault_free = root["fault_free"].as<bool>();
  auto pipeline = fdi::pipeline_config_from_yaml(root["pipeline"], yaml.source());
  if (!pipeline) return pipeline.error();
  spec.pipeline = pipeline.value();
  spec.pipeline_yaml = root["pipeline"] ? YAML::Dump(root["pipeline"]) : "{}";
  return spec;
}

FaultSpec fault_of(FaultKind kind, int gyro, double onset_s, double size) {
  FaultSpec f;
  f.kind = kind;
  f.gyro = gyro;
  f.at_s = onset_s;
  f.size = size;
  return f;
}

std::string opt_text(const std::optional<double>& v) {
  std::string out;
  if (v) append_double(out, *v);
  return out;
}

//! NaN (not available) as an empty field.
std::string num_text(double v) {
  return opt_text(std::isnan(v) ? std::nullopt : std::optional<double>(v));
}

}  // namespace

Result<CampaignSpec> read_campaign_spec(const std::string& path) {
  const YamlReader yaml{path};
  auto text = read_text_file(path);
  if (!text) return text.error();
  try {
    const YAML::Node root = YAML::Load(*text);
    if (!root || !root.IsMap()) return bad_input(path + ": expected a mapping (docs/campaign.md)");
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    auto spec = parse_spec(root, yaml, parent.empty() ? "." : parent.string());
    if (!spec) return spec.error();
    for (const Scenario& sc : spec->scenarios) {
      for (int g : spec->gyros) {
        if (g < 1 || g > sc.unit.gyro_count())
          return yaml.error(root["gyros"], "gyros",
                            "gyro " + std::to_string(g) + " does not exist in " + sc.name);
      }
    }
    return spec;
  } catch (const YAML::Exception& e) {
    return yaml.error(e, "");
  }
}

std::vector<CampaignCase> expand_campaign(const CampaignSpec& spec) {
  std::vector<CampaignCase> cases;
  const auto add = [&](std::size_t scenario, std::optional<FaultSpec> fault, std::uint64_t seed) {
    cases.push_back({cases.size(), scenario, std::move(fault), seed});
  };
  for (std::size_t s = 0; s < spec.scenarios.size(); ++s) {
    if (spec.fault_free) {
      for (std::uint64_t seed : spec.seeds) add(s, std::nullopt, seed);
    }
    for (FaultKind kind : spec.kinds) {
      std::vector<double> sizes = {0.0};
      for (const auto& [k, values] : spec.sizes) {
        if (k == kind) sizes = values;
      }
      for (int gyro : spec.gyros) {
        for (double onset : spec.onsets_s) {
          for (double size : sizes) {
            for (std::uint64_t seed : spec.seeds) add(s, fault_of(kind, gyro, onset, size), seed);
          }
        }
      }
    }
  }
  return cases;
}

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
  const double h = fdi::cusum_threshold(k, config.cusum_arl0_epochs);
  const double delta = std::abs(size_dps) * w[gyro - 1];
  if (delta <= k) return std::nullopt;
  return fdi::cusum_arl(delta, k, h) * dt_s;
}

std::string campaign_csv_header() {
  return "run,scenario,kind,gyro,onset_s,size,seed,outcome,isolated_gyro,detection_delay_s,isolation_delay_s,"
         "theory_delay_s,false_alarms,fault_free_s,final_knowledge_error_deg,final_sigma_deg,"
         "pointing_max_before_deg,pointing_rms_after_deg,pointing_max_after_deg,recover_s,bound_deg,"
         "max_wheel_momentum_fraction,wrong_gyro,wrong_at_s";
}

std::string campaign_csv_row(const CampaignRow& r) {
  std::string out = std::to_string(r.run) + "," + metadata_token(r.scenario) + "," + r.kind + "," +
                    std::to_string(r.gyro) + ",";
  append_double(out, r.onset_s);
  out += ',';
  append_double(out, r.size);
  out += "," + std::to_string(r.seed) + "," + std::string(outcome_name(r.fdi.outcome)) + ",";
  out += r.fdi.isolated_gyro ? std::to_string(*r.fdi.isolated_gyro) : std::string();
  out += "," + opt_text(r.fdi.detection_delay_s) + "," + opt_text(r.fdi.isolation_delay_s) + "," +
         opt_text(r.theory_delay_s) + "," + std::to_string(r.fdi.false_alarms) + ",";
  for (double v : {r.fdi.fault_free_s, r.final_knowledge_error_deg, r.final_sigma_deg,
                   r.pointing_max_before_deg, r.pointing_rms_after_deg, r.pointing_max_after_deg}) {
    out += num_text(v) + ",";
  }
  out += opt_text(r.recover_s) + "," + num_text(r.bound_deg) + "," + num_text(r.max_wheel_momentum_fraction) +
         ",";
  out += r.fdi.wrong_gyro ? std::to_string(*r.fdi.wrong_gyro) : std::string();
  out += "," + opt_text(r.fdi.wrong_at_s);
  return out;
}

Result<CampaignRow> parse_campaign_row(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream in(line);
  for (std::string field; std::getline(in, field, ',');) f.push_back(field);
  if (!line.empty() && line.back() == ',') f.emplace_back();
  if (f.size() != 24)
    return bad_input("campaign row with " + std::to_string(f.size()) + " fields (24 expected)");
  try {
    const auto num = [](const std::string& s) {
      return s.empty() ? std::numeric_limits<double>::quiet_NaN() : std::stod(s);
    };
    const auto opt = [](const std::string& s) {
      return s.empty() ? std::nullopt : std::optional<double>(std::stod(s));
    };
    CampaignRow r;
    r.run = std::stoul(f[0]);
    r.scenario = f[1];
    r.kind = f[2];
    r.gyro = std::stoi(f[3]);
    r.onset_s = num(f[4]);
    r.size = num(f[5]);
    r.seed = std::stoull(f[6]);
    bool known = false;
    for (Outcome o :
         {Outcome::kNone, Outcome::kRight, Outcome::kWrong, Outcome::kUnisolated, Outcome::kMissed}) {
      if (outcome_name(o) == f[7]) {
        r.fdi.outcome = o;
        known = true;
      }
    }
    if (!known) return bad_input("campaign row: unknown outcome '" + f[7] + "'");
    if (!f[8].empty()) r.fdi.isolated_gyro = std::stoi(f[8]);
    r.fdi.detection_delay_s = opt(f[9]);
    r.fdi.isolation_delay_s = opt(f[10]);
    r.theory_delay_s = opt(f[11]);
    r.fdi.false_alarms = std::stoi(f[12]);
    r.fdi.fault_free_s = num(f[13]);
    r.final_knowledge_error_deg = num(f[14]);
    r.final_sigma_deg = num(f[15]);
    r.pointing_max_before_deg = num(f[16]);
    r.pointing_rms_after_deg = num(f[17]);
    r.pointing_max_after_deg = num(f[18]);
    r.recover_s = opt(f[19]);
    r.bound_deg = num(f[20]);
    r.max_wheel_momentum_fraction = num(f[21]);
    if (!f[22].empty()) r.fdi.wrong_gyro = std::stoi(f[22]);
    r.fdi.wrong_at_s = opt(f[23]);
    return r;
  } catch (const std::exception&) {
    return bad_input("campaign row: a field is not a number");
  }
}

}  // namespace tetra::sim
