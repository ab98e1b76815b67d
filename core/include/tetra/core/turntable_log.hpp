#pragma once
// Turntable log (docs/interfaces.md §2.1), the input of `tetra calibrate`:
//   sequence,time_s,inner_deg,outer_deg,g1,...,gN
// `sequence` is the 1-based index in the rotation plan (pairs 2k−1, 2k are opposite rotations of the
// same gimbal at the same fixed angle of the other gimbal); encoder angles in degrees, wrapped or
// unwrapped; g in volts; N ≥ 3. The reader checks the format (columns, numbers, N ≥ 3, integral
// positive sequence numbers, every cell filled, time increasing within the file); what a sequence
// means is the calibration's business.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/result.hpp"

namespace tetra {

struct TurntableLog {
  std::string source;                                         //!< file name used in messages
  std::vector<std::pair<std::string, std::string>> metadata;  //!< "# key=value" comments
  int gyro_count = 0;                                         //!< N
  std::vector<int> sequence;                                  //!< plan index per row (1-based)
  std::vector<double> time_s;                                 //!< [s]
  std::vector<double> inner_deg;                              //!< [deg] inner gimbal encoder (body X)
  std::vector<double> outer_deg;                              //!< [deg] outer gimbal encoder
  std::vector<double> g_V;                                    //!< [V] rows×N row-major
  std::vector<std::size_t> lines;                             //!< 1-based file line of each row

  std::size_t rows() const { return time_s.size(); }
  double g(std::size_t row, int gyro_index0) const {
    return g_V[row * static_cast<std::size_t>(gyro_count) + static_cast<std::size_t>(gyro_index0)];
  }
  std::optional<std::string> meta(const std::string& key) const;
};

Result<TurntableLog> read_turntable_log(const std::string& path);
Result<TurntableLog> parse_turntable_log(std::string_view text, std::string source);

//! Formats a turntable log (comments first as "# key=value"); numbers in shortest round-trip form.
std::string format_turntable_log(const TurntableLog& log);
Status write_turntable_log(const std::string& path, const TurntableLog& log);

}  // namespace tetra
