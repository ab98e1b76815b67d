#pragma once
// The `ros2:` map of the fusion service's configuration (docs/ros2.md): an optional mirror of the
// attitude and health as ROS 2 messages on ROS 2 topic names.
//
//   ros2:
//     enabled: true
//     name: tetra_1                 # ROS name of the unit (default: the unit, made a valid ROS name)
//     frame_id: tetra_1_body        # the body frame: header.frame_id of the Imu message
//     reference_frame_id: tetra_1_reference  # the frame q_RB points into: header of QuaternionStamped

#include <string>

#include <yaml-cpp/yaml.h>

#include "tetra/core/result.hpp"
#include "tetra/core/yaml_reader.hpp"

namespace tetra::service {

struct Ros2ViewConfig {
  bool enabled = false;
  std::string name;                //!< "": ros2_name(unit)
  std::string frame_id;            //!< "": NAME_body
  std::string reference_frame_id;  //!< "": NAME_reference

  //! The settings with every default filled in for `unit`.
  Ros2ViewConfig resolved(const std::string& unit) const;
};

//! `unit` as a ROS 2 name token: letters, digits and single underscores, not starting with a digit
//! ("tetra-1" -> "tetra_1", "7x" -> "unit_7x").
std::string ros2_name(const std::string& unit);
//! True if `name` is a valid ROS 2 name token (what ros2_name() produces).
bool is_ros2_name(const std::string& name);

//! "ros2: off" or "ros2: rt/tetra/NAME/{attitude,imu}, rt/diagnostics (frames BODY, REFERENCE)".
std::string describe(const Ros2ViewConfig& config, const std::string& unit);

//! Parses the `ros2:` map; unknown keys and invalid names are errors naming the line.
Result<Ros2ViewConfig> ros2_view_config_from_yaml(const YAML::Node& node, const YamlReader& reader);

}  // namespace tetra::service
