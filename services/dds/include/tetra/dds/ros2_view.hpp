#pragma once
// The optional ROS 2 view of one unit (docs/ros2.md): each attitude mirrored as
// geometry_msgs/msg/QuaternionStamped on rt/tetra/NAME/attitude and sensor_msgs/msg/Imu on
// rt/tetra/NAME/imu, each Health as diagnostic_msgs/msg/DiagnosticArray on rt/diagnostics — ROS 2's own
// types (idl/ros2.idl), names and QoS, so `ros2 topic echo` reads them with no bridge.

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "ros2.h"  // generated from idl/ros2.idl
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::dds {

//! ROS 2's default QoS (rmw_qos_profile_default): reliable, volatile, keep-last 10 — matched by ROS 2
//! subscriptions with the default and with the sensor-data (best-effort) profiles — in XCDR1, the
//! representation ROS 2's middleware layers write and read.
Qos ros2_qos();

//! ROS 2 topic names of the view (with the DDS prefix "rt").
std::string ros2_attitude_topic(const std::string& name);  //!< rt/tetra/NAME/attitude
std::string ros2_imu_topic(const std::string& name);       //!< rt/tetra/NAME/imu
inline constexpr const char* kRos2DiagnosticsTopic = "rt/diagnostics";

//! [rad²/s²] covariance of the least-squares body rate from the gyros in `used`: (Σ h_i h_iᵀ / σ_i²)⁻¹
//! with σ_i = N_i / √dt, N_i the gyro's angle random walk (calibration `noise:`, else
//! `default_arw_dps_rtHz`). Fewer than 3 gyros, or axes that do not span 3-D: nullopt.
std::optional<Eigen::Matrix3d> rate_covariance(const Calibration& calibration, GyroMask used,
                                               double sample_rate_hz, double default_arw_dps_rtHz);

//! DiagnosticStatus level of a mode / gyro state (OK 0, WARN 1, ERROR 2, STALE 3).
std::uint8_t diagnostic_level(fdi::Mode mode);
std::uint8_t diagnostic_level(fdi::GyroState state);

//! The ROS 2 names of one unit's view, every default already filled in (docs/ros2.md).
struct Ros2Names {
  std::string name;                //!< ROS name of the unit: rt/tetra/NAME/...
  std::string frame_id;            //!< the body frame (Imu, DiagnosticArray headers)
  std::string reference_frame_id;  //!< the frame q_RB points into (QuaternionStamped header)
};

class Ros2View {
 public:
  struct Settings {
    Ros2Names names;
    std::string unit;         //!< hardware_id of the diagnostics
    Calibration calibration;  //!< gyro axes and noise, for the rate covariance
    double sample_rate_hz = 100.0;
    double default_arw_dps_rtHz = 3.0e-5;
  };
  //! Topics and writers on `participant`; the writers are XCDR1 whatever the process's default.
  static Result<Ros2View> create(const Participant& participant, Settings settings);

  //! QuaternionStamped and Imu of one attitude estimate.
  Status publish(const fdi::AttitudeEstimate& attitude);
  //! DiagnosticArray of one Health: a status for the unit and one per gyro.
  Status publish(const fdi::Health& health);

 private:
  Ros2View() = default;
  Settings settings_;
  std::optional<Topic> attitude_topic_, imu_topic_, diagnostics_topic_;
  std::optional<Writer<geometry_msgs_msg_dds__QuaternionStamped_>> attitude_writer_;
  std::optional<Writer<sensor_msgs_msg_dds__Imu_>> imu_writer_;
  std::optional<Writer<diagnostic_msgs_msg_dds__DiagnosticArray_>> diagnostics_writer_;
  //! The rate covariance of the gyros last in use (computed again only when they change).
  std::optional<std::pair<GyroMask, std::optional<Eigen::Matrix3d>>> rate_covariance_;
  // Storage the DiagnosticArray's strings and sequences point into (reused from one Health to the next).
  std::vector<std::array<std::string, 3>> status_text_;              //!< name, message, hardware_id
  std::vector<std::vector<std::array<std::string, 2>>> key_values_;  //!< key, value
  std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>> wire_values_;
  std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> wire_status_;
};

}  // namespace tetra::dds
