#include "tetra/fdi/config.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <variant>
#include <vector>

#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/yaml_reader.hpp"

namespace tetra::fdi {

namespace {

using Field = std::variant<double PipelineConfig::*, int PipelineConfig::*, bool PipelineConfig::*>;

struct KeyDef {
  const char* name;
  Field field;
};

// Every scalar key of the `pipeline:` map (latitude_deg and initial_q_wxyz are handled apart).
const std::vector<KeyDef>& scalar_keys() {
  static const std::vector<KeyDef> keys = {
      {"raw_units_dps", &PipelineConfig::raw_units_dps},
      {"sample_period_s", &PipelineConfig::sample_period_s},
      {"max_abs_raw_V", &PipelineConfig::max_abs_raw_V},
      {"max_abs_rate_dps", &PipelineConfig::max_abs_rate_dps},
      {"default_arw_dps_rtHz", &PipelineConfig::default_arw_dps_rtHz},
      {"default_bias_instability_dps", &PipelineConfig::default_bias_instability_dps},
      {"chi2_false_alarm_probability", &PipelineConfig::chi2_false_alarm_probability},
      {"cusum_min_fault_dps", &PipelineConfig::cusum_min_fault_dps},
      {"cusum_arl0_epochs", &PipelineConfig::cusum_arl0_epochs},
      {"rate_random_walk_horizon_s", &PipelineConfig::rate_random_walk_horizon_s},
      {"clear_after_s", &PipelineConfig::clear_after_s},
      {"isolation_window_s", &PipelineConfig::isolation_window_s},
      {"max_angular_acceleration_dps2", &PipelineConfig::max_angular_acceleration_dps2},
      {"onset_sigma", &PipelineConfig::onset_sigma},
      {"onset_pre_epochs", &PipelineConfig::onset_pre_epochs},
      {"onset_post_max_epochs", &PipelineConfig::onset_post_max_epochs},
      {"jump_false_alarm_probability", &PipelineConfig::jump_false_alarm_probability},
      {"onset_confirm_epochs", &PipelineConfig::onset_confirm_epochs},
      {"dropout_timeout_s", &PipelineConfig::dropout_timeout_s},
      {"max_gap_s", &PipelineConfig::max_gap_s},
      {"invalid_timeout_s", &PipelineConfig::invalid_timeout_s},
      {"stuck_repeat_count", &PipelineConfig::stuck_repeat_count},
      {"noise_window", &PipelineConfig::noise_window},
      {"noise_high_ratio", &PipelineConfig::noise_high_ratio},
      {"noise_low_ratio", &PipelineConfig::noise_low_ratio},
      {"spike_count", &PipelineConfig::spike_count},
      {"spike_window_s", &PipelineConfig::spike_window_s},
      {"reference_window_s", &PipelineConfig::reference_window_s},
      {"reference_sigma_arcsec", &PipelineConfig::reference_sigma_arcsec},
      {"reference_threshold_sigma", &PipelineConfig::reference_threshold_sigma},
      {"reference_confirm_count", &PipelineConfig::reference_confirm_count},
      {"glt_false_alarm_probability", &PipelineConfig::glt_false_alarm_probability},
      {"exclusion_enabled", &PipelineConfig::exclusion_enabled},
      {"filter_bias_isolation", &PipelineConfig::filter_bias_isolation},
      {"initial_sigma_deg", &PipelineConfig::initial_sigma_deg},
      {"bias_instability_correlation_s", &PipelineConfig::bias_instability_correlation_s},
      {"reference_gate_false_alarm_probability", &PipelineConfig::reference_gate_false_alarm_probability},
      {"reference_gate_reset_count", &PipelineConfig::reference_gate_reset_count},
      {"reference_check_window_s", &PipelineConfig::reference_check_window_s},
      {"reference_bias_window_s", &PipelineConfig::reference_bias_window_s},
      {"reference_check_false_alarm_probability", &PipelineConfig::reference_check_false_alarm_probability},
      {"reference_reaccept_s", &PipelineConfig::reference_reaccept_s},
      {"reference_noise_max_factor", &PipelineConfig::reference_noise_max_factor},
      {"reference_bias_arcsec", &PipelineConfig::reference_bias_arcsec},
      {"reference_latency_max_s", &PipelineConfig::reference_latency_max_s},
      {"reference_horizon_s", &PipelineConfig::reference_horizon_s},
      {"integrity_risk", &PipelineConfig::integrity_risk},
      {"calibration_error_sigmas", &PipelineConfig::calibration_error_sigmas},
  };
  return keys;
}

}  // namespace

Result<PipelineConfig> pipeline_config_from_yaml(const YAML::Node& node, const std::string& source) {
  PipelineConfig config;
  if (!node || node.IsNull()) return config;
  const YamlReader yaml{source};
  std::vector<std::string> allowed = {"latitude_deg", "initial_q_wxyz"};
  for (const auto& def : scalar_keys()) allowed.emplace_back(def.name);
  if (Status st = yaml.check_keys(node, allowed, "pipeline"); !st) return st.error();
  try {
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();
      const YAML::Node& value = kv.second;
      const std::string what = "pipeline." + key;
      if (key == "latitude_deg") {
        const auto v = yaml.number(value, what);
        if (!v) return v.error();
        config.latitude_deg = *v;
        continue;
      }
      if (key == "initial_q_wxyz") {
        if (!value.IsSequence() || value.size() != 4)
          return yaml.error(kv.first, what, "expected [w, x, y, z]");
        double q[4] = {};
        for (std::size_t k = 0; k < 4; ++k) {
          const auto c = yaml.number(value[k], what + "[" + std::to_string(k) + "]");
          if (!c) return c.error();
          q[k] = *c;
        }
        config.initial_q_RB = from_wxyz(q[0], q[1], q[2], q[3]);
        continue;
      }
      for (const auto& def : scalar_keys()) {
        if (key != def.name) continue;
        if (!value.IsScalar()) return yaml.error(kv.first, what, "expected a scalar");
        if (const auto* d = std::get_if<double PipelineConfig::*>(&def.field)) {
          const auto v = yaml.number(value, what);
          if (!v) return v.error();
          config.*(*d) = *v;
        } else if (const auto* i = std::get_if<int PipelineConfig::*>(&def.field)) {
          const auto v = yaml.number(value, what);
          if (!v) return v.error();
          if (*v != std::floor(*v) || std::abs(*v) > 1e9)
            return yaml.error(value, what, "must be a whole number");
          config.*(*i) = static_cast<int>(*v);
        } else {
          const std::string& b = value.Scalar();
          if (b != "true" && b != "false") return yaml.error(value, what, "'" + b + "' is not true or false");
          config.*std::get<bool PipelineConfig::*>(def.field) = b == "true";
        }
      }
    }
  } catch (const YAML::Exception& e) {
    return yaml.error(e, "pipeline");
  }
  if (auto st = validate(config); !st) return bad_input(source + ": " + st.error().message);
  return config;
}

Result<PipelineConfig> parse_pipeline_config(const std::string& yaml_text, const std::string& source) {
  const YamlReader yaml{source};
  auto loaded = yaml.load(yaml_text);
  if (!loaded) return loaded.error();
  const YAML::Node root = *loaded;
  if (!root || root.IsNull()) return PipelineConfig{};
  if (!root.IsMap()) return bad_input(source + ": expected a mapping with a 'pipeline:' key");
  if (Status st = yaml.check_keys(root, {"pipeline"}, ""); !st) return st.error();
  return pipeline_config_from_yaml(root["pipeline"], source);
}

Result<PipelineConfig> read_pipeline_config(const std::string& path) {
  auto text = read_input(path, kMaxYamlBytes);
  if (!text) return text.error();
  return parse_pipeline_config(*text, path);
}

Status validate(const PipelineConfig& c) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  auto probability = [](double v) { return std::isfinite(v) && v > 0.0 && v < 0.5; };
  auto within = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  auto at_least = [](double v, double lo) { return std::isfinite(v) && v >= lo; };
  if (c.latitude_deg && (!std::isfinite(*c.latitude_deg) || std::abs(*c.latitude_deg) > 90.0)) {
    return bad_input("pipeline.latitude_deg: must be within [-90, 90]");
  }
  const double qn = c.initial_q_RB.norm();
  if (!std::isfinite(qn) || std::abs(qn - 1.0) > 1e-3) {
    return bad_input("pipeline.initial_q_wxyz: must be a unit quaternion (norm within 1e-3 of 1)");
  }
  if (!std::isfinite(c.sample_period_s) || c.sample_period_s < 0.0) {
    return bad_input("pipeline.sample_period_s: must be >= 0 (0 = from the data)");
  }
  struct Check {
    const char* name;
    bool ok;
    const char* rule;
  };
  const Check checks[] = {
      {"max_abs_raw_V", positive(c.max_abs_raw_V), "> 0"},
      {"max_abs_rate_dps", positive(c.max_abs_rate_dps), "> 0"},
      {"default_arw_dps_rtHz", positive(c.default_arw_dps_rtHz), "> 0"},
      {"default_bias_instability_dps", at_least(c.default_bias_instability_dps, 0.0), ">= 0"},
      {"chi2_false_alarm_probability", probability(c.chi2_false_alarm_probability), "in (0, 0.5)"},
      {"cusum_min_fault_dps", positive(c.cusum_min_fault_dps), "> 0"},
      {"cusum_arl0_epochs", at_least(c.cusum_arl0_epochs, 10.0), ">= 10"},
      {"rate_random_walk_horizon_s", positive(c.rate_random_walk_horizon_s), "> 0"},
      {"clear_after_s", positive(c.clear_after_s), "> 0"},
      {"isolation_window_s", positive(c.isolation_window_s), "> 0"},
      {"max_angular_acceleration_dps2", positive(c.max_angular_acceleration_dps2), "> 0"},
      {"onset_sigma", positive(c.onset_sigma), "> 0"},
      {"onset_pre_epochs", c.onset_pre_epochs >= 2 && c.onset_pre_epochs <= 200, "in [2, 200]"},
      {"onset_post_max_epochs", c.onset_post_max_epochs >= 2 && c.onset_post_max_epochs <= 200,
       "in [2, 200]"},
      {"jump_false_alarm_probability", probability(c.jump_false_alarm_probability), "in (0, 0.5)"},
      {"onset_confirm_epochs", c.onset_confirm_epochs >= 2 && c.onset_confirm_epochs <= 100, "in [2, 100]"},
      {"dropout_timeout_s", positive(c.dropout_timeout_s), "> 0"},
      {"max_gap_s", positive(c.max_gap_s), "> 0"},
      {"invalid_timeout_s", positive(c.invalid_timeout_s), "> 0"},
      {"stuck_repeat_count", c.stuck_repeat_count >= 3, ">= 3"},
      {"noise_window", c.noise_window >= 8 && c.noise_window <= 256, "in [8, 256]"},
      {"noise_high_ratio", positive(c.noise_high_ratio - 1.0), "> 1"},
      {"noise_low_ratio", positive(c.noise_low_ratio) && c.noise_low_ratio < 1.0, "in (0, 1)"},
      {"spike_count", c.spike_count >= 2 && c.spike_count <= 64, "in [2, 64]"},
      {"spike_window_s", positive(c.spike_window_s), "> 0"},
      {"reference_window_s", positive(c.reference_window_s), "> 0"},
      {"reference_sigma_arcsec", positive(c.reference_sigma_arcsec), "> 0"},
      {"reference_threshold_sigma", positive(c.reference_threshold_sigma), "> 0"},
      {"reference_confirm_count", c.reference_confirm_count >= 1 && c.reference_confirm_count <= 100,
       "in [1, 100]"},
      {"glt_false_alarm_probability", probability(c.glt_false_alarm_probability), "in (0, 0.5)"},
      {"initial_sigma_deg", within(c.initial_sigma_deg, 0.0, 180.0), "in [0, 180]"},
      {"bias_instability_correlation_s", positive(c.bias_instability_correlation_s), "> 0"},
      {"reference_gate_false_alarm_probability", probability(c.reference_gate_false_alarm_probability),
       "in (0, 0.5)"},
      {"reference_gate_reset_count",
       c.reference_gate_reset_count >= 1 && c.reference_gate_reset_count <= 1000, "in [1, 1000]"},
      {"reference_check_window_s", positive(c.reference_check_window_s), "> 0"},
      {"reference_bias_window_s", positive(c.reference_bias_window_s), "> 0"},
      {"reference_check_false_alarm_probability", probability(c.reference_check_false_alarm_probability),
       "in (0, 0.5)"},
      {"reference_reaccept_s", at_least(c.reference_reaccept_s, 0.0), ">= 0"},
      {"reference_noise_max_factor", within(c.reference_noise_max_factor, 1.0, 100.0), "in [1, 100]"},
      {"reference_bias_arcsec", at_least(c.reference_bias_arcsec, 0.0), ">= 0"},
      {"reference_latency_max_s", within(c.reference_latency_max_s, 0.0, 10.0), "in [0, 10]"},
      {"reference_horizon_s", within(c.reference_horizon_s, 0.0, 10.0), "in [0, 10]"},
      {"integrity_risk", probability(c.integrity_risk), "in (0, 0.5)"},
      {"calibration_error_sigmas", within(c.calibration_error_sigmas, 0.0, 100.0), "in [0, 100]"},
  };
  for (const auto& check : checks) {
    if (!check.ok) return bad_input(std::string("pipeline.") + check.name + ": must be " + check.rule);
  }
  return ok_status();
}

std::string describe(const PipelineConfig& c) {
  std::string out;
  out += "latitude_deg: ";
  if (c.latitude_deg) {
    append_double(out, *c.latitude_deg);
  } else {
    out += "none (no Earth-rate removal)";
  }
  out += "\ninitial_q_wxyz: [";
  const auto q = to_wxyz(c.initial_q_RB);
  for (std::size_t i = 0; i < 4; ++i) {
    if (i) out += ", ";
    append_double(out, q[i]);
  }
  out += "]\n";
  for (const auto& def : scalar_keys()) {
    out += def.name;
    out += ": ";
    if (const auto* d = std::get_if<double PipelineConfig::*>(&def.field)) {
      append_double(out, c.*(*d));
    } else if (const auto* i = std::get_if<int PipelineConfig::*>(&def.field)) {
      append_int(out, c.*(*i));
    } else {
      out += (c.*std::get<bool PipelineConfig::*>(def.field)) ? "true" : "false";
    }
    out += '\n';
  }
  return out;
}

}  // namespace tetra::fdi
