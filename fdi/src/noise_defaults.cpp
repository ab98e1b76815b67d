#include "tetra/fdi/noise_defaults.hpp"

#include <sstream>

namespace tetra::fdi {

Calibration with_default_noise(Calibration cal, const PipelineConfig& config) {
  for (auto& g : cal.gyros) {
    if (g.noise) continue;  // a stated section is taken as it is (an absent term there is zero)
    GyroNoise n;
    n.arw_dps_rtHz = config.default_arw_dps_rtHz;
    n.bias_instability_dps = config.default_bias_instability_dps;
    g.noise = n;
  }
  return cal;
}

std::string default_noise_warning(const Calibration& cal, const PipelineConfig& config) {
  std::string ids;
  for (const auto& g : cal.gyros) {
    if (!g.noise) ids += (ids.empty() ? "" : ", ") + std::to_string(g.id);
  }
  if (ids.empty()) return "";
  std::ostringstream out;
  out << "no noise: section for gyro " << ids
      << "; running on the conservative defaults N = " << config.default_arw_dps_rtHz
      << " deg/rt-s, B = " << config.default_bias_instability_dps
      << " deg/s (pipeline default_arw_dps_rtHz, default_bias_instability_dps): sigma is honest only if the "
         "unit"
         " is no noisier; add the section from tetra allan";
  return out.str();
}

}  // namespace tetra::fdi
