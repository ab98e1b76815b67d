#pragma once
// What the pipeline assumes for a gyro whose calibration does not state its noise (a calibration as
// `tetra calibrate` writes it has no `noise:` section): conservative defaults, said aloud (docs/fdi.md,
// "Calibration without noise").

#include <string>

#include "tetra/core/calibration_file.hpp"
#include "tetra/fdi/config.hpp"

namespace tetra::fdi {

//! The calibration with a `noise:` section for every gyro that has none: white noise N and bias instability B
//! from the configuration's defaults (`default_arw_dps_rtHz`, `default_bias_instability_dps`). A stated
//! section is kept as it is (a term absent there is zero, as before).
Calibration with_default_noise(Calibration cal, const PipelineConfig& config);

//! One line saying which gyros run on the defaults, or "" when every gyro has a `noise:` section.
std::string default_noise_warning(const Calibration& cal, const PipelineConfig& config);

}  // namespace tetra::fdi
