#include "tetra/dds/ros2_view.hpp"

#include <cmath>

#include "tetra/core/csv.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/core/rate_covariance.hpp"
#include "tetra/core/units.hpp"

namespace tetra::dds {

namespace {

constexpr int kRos2Depth = 10;               // rmw_qos_profile_default's depth
constexpr double kUnknownCovariance = -1.0;  // sensor_msgs/Imu: element 0 = -1, the field is not measured

//! std_msgs/Header: the stamp as builtin_interfaces/Time (whole seconds, floor, and the nanoseconds
//! after them); the frame id's text stays owned by the caller (the writer only reads it).
std_msgs_msg_dds__Header_ ros2_header(std::int64_t stamp_ns, const std::string& frame_id) {
  std::int64_t sec = stamp_ns / kNanosPerSecond;
  std::int64_t nanosec = stamp_ns % kNanosPerSecond;
  if (nanosec < 0) {
    sec -= 1;
    nanosec += kNanosPerSecond;
  }
  std_msgs_msg_dds__Header_ header{};
  header.stamp.sec = static_cast<std::int32_t>(sec);
  header.stamp.nanosec = static_cast<std::uint32_t>(nanosec);
  header.frame_id = const_cast<char*>(frame_id.c_str());
  return header;
}

void set_covariance(double (&out)[9], const Eigen::Matrix3d& covariance) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[3 * r + c] = covariance(r, c);  // row-major, as ROS 2 stores it
  }
}

std::string number_text(double value) {
  std::string out;
  append_double(out, value);
  return out;
}

template <class T>
Status create_writer(const Participant& participant, std::optional<Topic>& topic,
                     std::optional<Writer<T>>& writer, const dds_topic_descriptor_t* descriptor,
                     const std::string& name) {
  auto t = Topic::create(participant, descriptor, name, ros2_qos());
  if (!t) return t.error();
  topic.emplace(std::move(t).value());
  auto w = Writer<T>::create(participant, *topic, ros2_qos());
  if (!w) return w.error();
  writer.emplace(std::move(w).value());
  return ok_status();
}

}  // namespace

Qos ros2_qos() {
  Qos qos;
  qos.reliable().volatile_durability().keep_last(kRos2Depth).data_representation(DataRepresentation::kXcdr1);
  return qos;
}

std::string ros2_attitude_topic(const std::string& name) {
  return "rt/tetra/" + name + "/attitude";
}
std::string ros2_imu_topic(const std::string& name) {
  return "rt/tetra/" + name + "/imu";
}

std::optional<Eigen::Matrix3d> rate_covariance(const Calibration& calibration, GyroMask used,
                                               double sample_rate_hz, double default_arw_dps_rtHz) {
  std::vector<Eigen::Vector3d> axes;
  std::vector<double> sigmas_rad_s;
  for (const GyroCalibration& gyro : calibration.gyros) {
    if (!has_gyro(used, gyro.id)) continue;
    const double arw_dps_rtHz =
        gyro.noise && gyro.noise->arw_dps_rtHz ? *gyro.noise->arw_dps_rtHz : default_arw_dps_rtHz;
    axes.push_back(gyro.axis_B);
    sigmas_rad_s.push_back(arw_dps_rtHz * kDegToRad * std::sqrt(sample_rate_hz));  // N / √dt
  }
  return least_squares_rate_covariance(axes, sigmas_rad_s);
}

std::uint8_t diagnostic_level(fdi::Mode mode) {
  switch (mode) {
    case fdi::Mode::kNominal:
      return 0;
    case fdi::Mode::kDegraded:
    case fdi::Mode::kSuspect:
      return 1;
    case fdi::Mode::kLost:
      return 2;
  }
  return 2;
}
std::uint8_t diagnostic_level(fdi::GyroState state) {
  switch (state) {
    case fdi::GyroState::kOk:
      return 0;
    case fdi::GyroState::kSuspect:
      return 1;
    case fdi::GyroState::kInvalid:
    case fdi::GyroState::kExcluded:
      return 2;
    case fdi::GyroState::kAbsent:
      return 3;  // STALE: no data
  }
  return 2;
}

Result<Ros2View> Ros2View::create(const Participant& participant, Settings settings) {
  Ros2View view;
  view.settings_ = std::move(settings);
  const std::string& name = view.settings_.names.name;
  if (auto s = create_writer(participant, view.attitude_topic_, view.attitude_writer_,
                             &geometry_msgs_msg_dds__QuaternionStamped__desc, ros2_attitude_topic(name));
      !s)
    return s.error();
  if (auto s = create_writer(participant, view.imu_topic_, view.imu_writer_, &sensor_msgs_msg_dds__Imu__desc,
                             ros2_imu_topic(name));
      !s)
    return s.error();
  if (auto s = create_writer(participant, view.diagnostics_topic_, view.diagnostics_writer_,
                             &diagnostic_msgs_msg_dds__DiagnosticArray__desc, kRos2DiagnosticsTopic);
      !s)
    return s.error();
  return view;
}

Status Ros2View::publish(const fdi::AttitudeEstimate& attitude) {
  // tetra's q_RB (body -> reference, Hamilton, scalar first) is ROS's orientation of the body frame in
  // the reference frame; ROS writes it x, y, z, w.
  geometry_msgs_msg_dds__Quaternion_ q{};
  q.x = attitude.q_RB.x();
  q.y = attitude.q_RB.y();
  q.z = attitude.q_RB.z();
  q.w = attitude.q_RB.w();

  geometry_msgs_msg_dds__QuaternionStamped_ stamped{};
  stamped.header = ros2_header(attitude.stamp_ns, settings_.names.reference_frame_id);
  stamped.quaternion = q;
  if (auto s = attitude_writer_->write(stamped); !s) return s;

  sensor_msgs_msg_dds__Imu_ imu{};
  imu.header = ros2_header(attitude.stamp_ns, settings_.names.frame_id);
  imu.orientation = q;
  set_covariance(imu.orientation_covariance, attitude.sigma_rad.cwiseAbs2().asDiagonal().toDenseMatrix());
  imu.angular_velocity.x = attitude.omega_BR_B_rad_s.x();
  imu.angular_velocity.y = attitude.omega_BR_B_rad_s.y();
  imu.angular_velocity.z = attitude.omega_BR_B_rad_s.z();
  if (!rate_covariance_ || rate_covariance_->first != attitude.gyros) {  // only when the gyros in use change
    rate_covariance_.emplace(attitude.gyros,
                             rate_covariance(settings_.calibration, attitude.gyros, settings_.sample_rate_hz,
                                             settings_.default_arw_dps_rtHz));
  }
  if (const auto& rate = rate_covariance_->second) {
    set_covariance(imu.angular_velocity_covariance, *rate);
  } else {
    imu.angular_velocity_covariance[0] = kUnknownCovariance;
  }
  imu.linear_acceleration_covariance[0] = kUnknownCovariance;  // a gyro package measures no acceleration
  return imu_writer_->write(imu);
}

Status Ros2View::publish(const fdi::Health& health) {
  const std::size_t n = 1 + health.gyros.size();
  status_text_.resize(n);
  key_values_.resize(n);
  wire_values_.resize(n);
  wire_status_.resize(n);
  const std::string prefix = "tetra/" + settings_.names.name;
  const int n_gyros = static_cast<int>(health.gyros.size());

  // The unit: mode and the fault-detection statistics.
  status_text_[0] = {
      prefix + ": fusion",
      std::string("mode ") + fdi::to_string(health.mode) + ", gyros " + mask_to_string(health.used, n_gyros),
      settings_.unit};
  key_values_[0] = {{"mode", fdi::to_string(health.mode)},
                    {"gyros_used", mask_to_string(health.used, n_gyros)},
                    {"parity_residual", number_text(health.parity_residual)},
                    {"chi2", number_text(health.chi2)},
                    {"chi2_threshold", number_text(health.chi2_threshold)},
                    {"cusum", number_text(health.cusum)},
                    {"cusum_threshold", number_text(health.cusum_threshold)}};
  wire_status_[0].level = diagnostic_level(health.mode);
  // Each gyro: its state and the fault it was excluded or suspected for.
  for (std::size_t i = 0; i < health.gyros.size(); ++i) {
    const fdi::GyroHealth& gyro = health.gyros[i];
    status_text_[i + 1] = {
        prefix + ": gyro " + std::to_string(i + 1),
        std::string(fdi::to_string(gyro.state)) +
            (gyro.kind == fdi::FaultKind::kNone ? "" : std::string(", ") + fdi::to_string(gyro.kind)),
        settings_.unit};
    key_values_[i + 1] = {{"state", fdi::to_string(gyro.state)}, {"fault", fdi::to_string(gyro.kind)}};
    wire_status_[i + 1].level = diagnostic_level(gyro.state);
  }
  for (std::size_t i = 0; i < n; ++i) {
    auto& status = wire_status_[i];
    status.name = status_text_[i][0].data();
    status.message = status_text_[i][1].data();
    status.hardware_id = status_text_[i][2].data();
    wire_values_[i].resize(key_values_[i].size());
    for (std::size_t k = 0; k < key_values_[i].size(); ++k) {
      wire_values_[i][k].key = key_values_[i][k][0].data();
      wire_values_[i][k].value = key_values_[i][k][1].data();
    }
    status.values._length = status.values._maximum = static_cast<std::uint32_t>(wire_values_[i].size());
    status.values._buffer = wire_values_[i].data();
    status.values._release = false;
  }
  diagnostic_msgs_msg_dds__DiagnosticArray_ array{};
  array.header = ros2_header(health.stamp_ns, settings_.names.frame_id);
  array.status._length = array.status._maximum = static_cast<std::uint32_t>(n);
  array.status._buffer = wire_status_.data();
  array.status._release = false;
  return diagnostics_writer_->write(array);
}

}  // namespace tetra::dds
