#pragma once
// Configuration of `tetra fusion` (YAML, docs/dds.md): a struct with in-class defaults, validated
// once, echoed at start-up. The `pipeline:` map is the fusion pipeline's own configuration, the same
// one `tetra replay --config` reads.

#include <cstdint>
#include <optional>
#include <string>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/service/epoch_assembler.hpp"
#include "tetra/service/ros2_view_config.hpp"
#include "tetra/service/security_profile.hpp"

namespace tetra::service {

//! Which thread runs an epoch once its samples arrive (docs/dds.md, "Latency").
enum class GyroDispatch {
  kListener,  //!< Cyclone's receive thread, through a data-available listener: no thread wake-up
  kWaitset,   //!< the service's waitset thread, woken by the gyro reader's read condition
};

constexpr double kDefaultClockWindow_s = 0.1;  //!< [s] (docs/dds.md, "Epoch assembly")

//! [s] the clock window when none is configured: 0.1 s, or 4 sample periods if longer.
double default_clock_window_s(double sample_rate_hz);

struct FusionConfig {
  std::string unit = "tetra-1";   //!< key of every topic this service reads and writes
  std::string calibration_path;   //!< calibration YAML (relative paths: to the config file)
  double sample_rate_hz = 100.0;  //!< [Hz] nominal gyro rate (sensor time)
  double speed = 1.0;  //!< [-] sensor seconds per wall-clock second: 1 for a real sensor, X for a simulator X
                       //!< times faster
  std::optional<double>
      tolerance_s;              //!< [s] stamps this close belong to one epoch (< period/2); default period/4
  double max_latency_s = 0.02;  //!< [s] longest wait for an epoch's missing samples
  std::optional<double> clock_window_s;  //!< [s] how far a stamp may lead the unit's clock; default
                                         //!< kDefaultClockWindow_s or 4 periods, the larger
  double health_period_s = 0.5;          //!< [s] Health at least this often (and on every change)
  GyroDispatch gyro_dispatch = GyroDispatch::kListener;  //!< `gyro_dispatch: listener | waitset`
  fdi::PipelineConfig pipeline;                          //!< the `pipeline:` map
  Calibration calibration;                               //!< read from calibration_path
  std::optional<SecurityProfile> security;  //!< `security: PROFILE.yaml` (opt-in DDS Security; relative: to
                                            //!< the config file)
  Ros2ViewConfig ros2;                      //!< `ros2:` the optional ROS 2 view (docs/ros2.md)
  //! `tetra fusion --realtime[=PRIORITY]` (not a key of the file): memory locked and the receive/step
  //! threads under SCHED_FIFO at this priority (tetra/service/realtime.hpp); none: default scheduling.
  std::optional<int> realtime_priority;
  std::string source;  //!< the config file, for messages

  //! [ns] wall-clock time after which a silent gyro is absent: 3 sample periods / speed.
  std::int64_t deadline_ns() const;
  //! The assembler's settings for `gyro_count` gyros.
  AssemblerConfig assembler(int gyro_count) const;
};

//! Reads the file and the calibration it names. Unknown keys are errors naming the line.
Result<FusionConfig> read_fusion_config(const std::string& path);
Result<FusionConfig> parse_fusion_config(const std::string& yaml_text, const std::string& source,
                                         const std::string& base_dir);
Status validate(const FusionConfig& config);
std::string describe(const FusionConfig& config);

}  // namespace tetra::service
