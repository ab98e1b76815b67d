// libFuzzer target: what `tetra calibrate` does with a file — the turntable log reader, the encoder
// interpretation (analyze_turntable) and both estimators — on arbitrary bytes. The first byte picks
// the latitude and the method, the rest is the file. An estimate that comes back must be a valid
// calibration (finite, unit axes, non-zero scale factors).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "tetra/core/calibration.hpp"
#include "tetra/core/turntable_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t knobs = data[0];
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  const auto log = tetra::parse_turntable_log(text, "fuzz.csv");
  if (!log) return 0;  // the reader has its own target
  const double latitude_deg = -90.0 + 180.0 * static_cast<double>(knobs & 0x3f) / 63.0;
  const auto motion = tetra::analyze_turntable(*log, latitude_deg);
  if (!motion) {
    tetra::fuzz::check_error_message(motion.error());
    return 0;
  }
  tetra::CalibrationOptions options;
  options.method =
      (knobs & 0x40) != 0 ? tetra::CalibrationMethod::kBatch : tetra::CalibrationMethod::kSixteen;
  options.bias_model = (knobs & 0x80) != 0 ? tetra::BiasModel::kSeed : tetra::BiasModel::kBody;
  const auto result = tetra::calibrate(*log, *motion, options);
  if (!result) {
    tetra::fuzz::check_error_message(result.error());
    return 0;
  }
  const auto valid = tetra::validate_calibration(result->calibration, "estimate");
  if (!valid) {
    std::fprintf(stderr, "calibrate returned an invalid calibration: %s\n", valid.error().message.c_str());
    TETRA_FUZZ_CHECK(valid.ok());
  }
  const auto fit = tetra::evaluate_calibration(*log, *motion, result->calibration);
  if (!fit) tetra::fuzz::check_error_message(fit.error());
  return 0;
}
