#include "tetra/service/fusion_config.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "tetra/core/input_files.hpp"
#include "tetra/core/units.hpp"
#include "tetra/core/yaml_reader.hpp"
#include "tetra/service/unit_name.hpp"

namespace tetra::service {

namespace {

std::int64_t to_ns(double seconds) {
  return seconds_to_ns(seconds);
}

}  // namespace

std::int64_t FusionConfig::deadline_ns() const {
  return to_ns(3.0 / (sample_rate_hz * speed));
}

double default_clock_window_s(double sample_rate_hz) {
  return std::min(std::max(kDefaultClockWindow_s, 4.0 / sample_rate_hz), 1e6);  // bounded: converted to ns
}

AssemblerConfig FusionConfig::assembler(int gyro_count) const {
  AssemblerConfig config;
  config.gyro_count = gyro_count;
  config.nominal_period_ns = to_ns(1.0 / sample_rate_hz);
  config.tolerance_ns = tolerance_s ? to_ns(*tolerance_s) : config.nominal_period_ns / 4;
  config.max_latency_ns = to_ns(max_latency_s);
  config.clock_window_ns = to_ns(clock_window_s ? *clock_window_s : default_clock_window_s(sample_rate_hz));
  config.speed = speed;
  return config;
}

Result<FusionConfig> read_fusion_config(const std::string& path) {
  auto text = read_input(path, kMaxYamlBytes);
  if (!text) return text.error();
  const auto dir = std::filesystem::path(path).parent_path().string();
  return parse_fusion_config(*text, path, dir);
}

Result<FusionConfig> parse_fusion_config(const std::string& yaml_text, const std::string& source,
                                         const std::string& base_dir) {
  const YamlReader reader(source);
  auto loaded = reader.load(yaml_text);
  if (!loaded) return loaded.error();
  const YAML::Node root = std::move(loaded).value();
  if (!root.IsMap()) return bad_input(source + ": expected a YAML map of settings");
  FusionConfig config;
  config.source = source;
  if (auto keys = reader.check_keys(
          root,
          {"unit", "calibration", "sample_rate_hz", "speed", "tolerance_s", "max_latency_s", "clock_window_s",
           "health_period_s", "gyro_dispatch", "pipeline", "security", "ros2"},
          "");
      !keys) {
    return keys.error();
  }
  for (const auto& item : root) {
    const std::string& key = item.first.Scalar();
    const YAML::Node& value = item.second;
    if (key == "unit" || key == "calibration") {
      if (!value.IsScalar()) return bad_input(reader.at(value) + key + " must be text");
      if (key == "unit") {
        if (auto status = check_unit_name(value.Scalar(), reader.at(value) + "unit"); !status)
          return status.error();
      }
      (key == "unit" ? config.unit : config.calibration_path) = value.Scalar();
    } else if (key == "gyro_dispatch") {
      const std::string text = value.IsScalar() ? value.Scalar() : std::string();
      if (text != "listener" && text != "waitset")
        return bad_input(reader.at(value) + "gyro_dispatch must be 'listener' or 'waitset'");
      config.gyro_dispatch = text == "listener" ? GyroDispatch::kListener : GyroDispatch::kWaitset;
    } else if (key == "security") {
      if (!value.IsScalar()) return bad_input(reader.at(value) + "security must be a file name");
      std::filesystem::path profile_path(value.Scalar());
      if (profile_path.is_relative() && !base_dir.empty())
        profile_path = std::filesystem::path(base_dir) / profile_path;
      auto profile = read_security_profile(profile_path.string());
      if (!profile) return bad_input(reader.at(value) + "security: " + profile.error().message);
      config.security = std::move(profile).value();
    } else if (key == "ros2") {
      auto ros2 = ros2_view_config_from_yaml(value, reader);
      if (!ros2) return ros2.error();
      config.ros2 = std::move(ros2).value();
    } else if (key == "pipeline") {
      auto pipeline = fdi::pipeline_config_from_yaml(value, source);
      if (!pipeline) return pipeline.error();
      config.pipeline = std::move(pipeline).value();
    } else {
      auto x = reader.number(value, key);
      if (!x) return x.error();
      if (key == "sample_rate_hz") config.sample_rate_hz = *x;
      if (key == "speed") config.speed = *x;
      if (key == "tolerance_s") config.tolerance_s = *x;
      if (key == "max_latency_s") config.max_latency_s = *x;
      if (key == "clock_window_s") config.clock_window_s = *x;
      if (key == "health_period_s") config.health_period_s = *x;
    }
  }
  if (config.calibration_path.empty())
    return bad_input(source + ": missing key 'calibration' (a calibration YAML)");
  std::filesystem::path cal(config.calibration_path);
  if (cal.is_relative() && !base_dir.empty()) cal = std::filesystem::path(base_dir) / cal;
  config.calibration_path = cal.string();
  auto calibration = read_calibration(config.calibration_path);
  if (!calibration) return calibration.error();
  config.calibration = std::move(calibration).value();
  if (auto status = validate(config); !status) return status.error();
  return config;
}

Status validate(const FusionConfig& config) {
  const std::string& s = config.source;
  if (auto status = check_unit_name(config.unit, s + ": unit"); !status) return status;
  if (!(config.sample_rate_hz >= 0.001 && config.sample_rate_hz <= 100000.0)) {
    return bad_input(s + ": sample_rate_hz must be in [0.001, 100000]");
  }
  if (!(config.speed > 0.0 && config.speed <= 1000.0)) return bad_input(s + ": speed must be in (0, 1000]");
  if (!(config.health_period_s > 0.0 && config.health_period_s <= 1.0)) {
    return bad_input(s + ": health_period_s must be in (0, 1] (Health is published at least at 1 Hz)");
  }
  if (config.calibration.gyro_count() > 16) return bad_input(s + ": at most 16 gyros go on the wire");
  // Before the assembler's settings are converted to integer nanoseconds.
  const double period_s = 1.0 / config.sample_rate_hz;
  if (config.tolerance_s && !(*config.tolerance_s >= 0.0 && *config.tolerance_s < period_s / 2)) {
    return bad_input(s + ": tolerance_s must be in [0, period/2) = [0, " + std::to_string(period_s / 2) +
                     ")");
  }
  if (!(config.max_latency_s > 0.0 && config.max_latency_s <= 60.0)) {
    return bad_input(s + ": max_latency_s must be in (0, 60]");
  }
  if (config.clock_window_s &&
      !(*config.clock_window_s >= 2 * period_s && *config.clock_window_s <= 3600.0)) {
    return bad_input(s + ": clock_window_s must be in [2 sample periods, 3600] = [" +
                     std::to_string(2 * period_s) + ", 3600]");
  }
  if (auto status = validate(config.assembler(config.calibration.gyro_count())); !status) {
    return bad_input(s + ": " + status.error().message);
  }
  return fdi::validate(config.pipeline);
}

std::string describe(const FusionConfig& config) {
  std::ostringstream out;
  out << "unit: " << config.unit << '\n'
      << "calibration: " << config.calibration_path << " (" << config.calibration.gyro_count()
      << " gyros, method " << config.calibration.method << ")\n"
      << "sample_rate_hz: " << config.sample_rate_hz << '\n'
      << "speed: " << config.speed << " (deadline " << ns_to_seconds(config.deadline_ns()) << " s)\n"
      << "tolerance_s: "
      << (config.tolerance_s ? std::to_string(*config.tolerance_s)
                             : "a quarter period (" + std::to_string(0.25 / config.sample_rate_hz) + ")")
      << '\n'
      << "max_latency_s: " << config.max_latency_s << '\n'
      << "clock_window_s: "
      << (config.clock_window_s ? *config.clock_window_s : default_clock_window_s(config.sample_rate_hz))
      << '\n'
      << "health_period_s: " << config.health_period_s << '\n'
      << "gyro_dispatch: " << (config.gyro_dispatch == GyroDispatch::kListener ? "listener" : "waitset")
      << '\n'
      << (config.security ? describe(*config.security) : std::string("security: none")) << '\n'
      << describe(config.ros2, config.unit) << '\n'
      << "realtime: "
      << (config.realtime_priority
              ? "memory locked, SCHED_FIFO priority " + std::to_string(*config.realtime_priority) +
                    " for the receive/step threads"
              : std::string("off"))
      << '\n'
      << "pipeline:\n"
      << fdi::describe(config.pipeline);
  return out.str();
}

}  // namespace tetra::service
