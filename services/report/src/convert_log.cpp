// Gyro log conversion (tetra/report/convert_log.hpp).
#include "tetra/report/convert_log.hpp"

#include <array>
#include <cmath>
#include <optional>
#include <span>

#include "tetra/core/gyro_log.hpp"
#include "tetra/core/output_files.hpp"

namespace tetra::report {

Result<ConvertedLog> convert_gyro_log(const ConvertLogOptions& o) {
  RunFiles files;
  files.add_input(o.in_path, name_of(o.names, "in_path"));
  auto out = files.add(o.out_path, name_of(o.names, "out_path"));
  if (!out) return out.error();
  auto reader = GyroLogReader::open(o.in_path);
  if (!reader) return reader.error();
  const GyroLog& head = (*reader)->header();
  GyroLogWriter writer;
  writer.set_hdf5_compression(o.compress);
  if (Status s = writer.open_like(**out, head); !s) return s.error();
  const auto ng = static_cast<std::size_t>(head.gyro_count);
  ConvertedLog converted;
  GyroLog block;
  while (true) {
    auto more = (*reader)->next(block);
    if (!more) return more.error();
    if (!*more) break;
    for (std::size_t k = 0; k < block.epochs(); ++k) {
      const std::span<const double> values(block.values.data() + k * ng, ng);
      const std::span<const std::uint8_t> present(block.present.data() + k * ng, ng);
      std::optional<std::array<double, 4>> ref;
      if (block.has_reference && block.reference_present[k] != 0) ref = block.reference_wxyz[k];
      std::optional<double> ref_stamp;
      if (block.has_reference_stamp && std::isfinite(block.reference_stamp_s[k]))
        ref_stamp = block.reference_stamp_s[k];
      if (Status s = writer.write(block.time_s[k], values, present, ref, ref_stamp); !s) return s.error();
    }
    converted.epochs += block.epochs();
  }
  if (Status s = writer.close(); !s) return s.error();
  if (Status s = files.commit(); !s) return s.error();
  return converted;
}

}  // namespace tetra::report
