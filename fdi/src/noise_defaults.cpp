#include "tetra/fdi/noise_defaults.hpp"

#include <sstream>

namespace tetra::fdi {

Calibration with_default_noise(Calibration cal, const PipelineConfig& config) {
  for (auto& g : cal.gyros) {
    GyroNoise n = g.noise.value_or(GyroNoise{});
    if (!n.arw_dps_rtHz) n.arw_dps_rtHz = config.default_arw_dps_rtHz;
    if (!n.bias_instability_dps) n.bias_instability_dps = config.default_bias_instability_dps;
    g.noise = n;
  }
  return cal;
}

std::string default_noise_warning(const Calibration& cal, const PipelineConfig& config) {
  std::string arw;
  std::string bias;
  for (const auto& g : cal.gyros) {
    const std::string id = (arw.empty() ? "" : ", ") + std::to_string(g.id);
    const std::string idb = (bias.empty() ? "" : ", ") + std::to_string(g.id);
    if (!g.noise || !g.noise->arw_dps_rtHz) arw += id;
    if (!g.noise || !g.noise->bias_instability_dps) bias += idb;
  }
  if (arw.empty() && bias.empty()) return "";
  std::ostringstream out;
  out << "no measured noise (noise: section) for";
  if (!arw.empty()) out << " arw_dps_rtHz of gyro " << arw;
  if (!arw.empty() && !bias.empty()) out << " and";
  if (!bias.empty()) out << " bias_instability_dps of gyro " << bias;
  out << "; running on the conservative defaults N = " << config.default_arw_dps_rtHz
      << " deg/rt-s, B = " << config.default_bias_instability_dps
      << " deg/s (pipeline default_arw_dps_rtHz, default_bias_instability_dps): sigma is honest only if the"
         " unit is no noisier; add the section from tetra allan";
  return out.str();
}

}  // namespace tetra::fdi
