#pragma once
// The operator commands of a recorded run (`tetra record --commands`, JSON lines): each as the
// service obeyed or refused it, stamped with the sensor time of the last epoch before it. `tetra
// replay --commands` applies them at the same place in the epoch stream, so replay equals the
// service across commands.

#include <cstdint>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/fdi/pipeline.hpp"

namespace tetra::report {

struct RecordedCommand {
  std::int64_t stamp_ns = 0;  //!< [ns] sensor time of the last epoch the service had fused
  std::string action;         //!< "reset", "exclude", "reinstate"
  int gyro = 0;
  bool force = false;
};

//! Reads a command log; errors name the file, line and field.
Result<std::vector<RecordedCommand>> read_command_log(const std::string& path);

//! Applies `command` to `pipeline` as the service did; returns the acknowledgement.
fdi::FdiEvent apply(fdi::Pipeline& pipeline, const RecordedCommand& command);

}  // namespace tetra::report
