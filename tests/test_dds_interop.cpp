// Interoperability of tetra's topics with other DDS peers (docs/dds.md "Data representation",
// docs/ros2.md): plain Cyclone DDS readers restricted to XCDR1 or to XCDR2 read every tetra topic, and
// readers using ROS 2's type names, topic names and QoS read the ROS 2 view. The service, simulator and
// command tool run as separate processes on loopback; each test has its own domain id.
// Waits poll with a generous upper bound that only turns a hang into a failure; nothing asserts on time.

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "ros2.h"
#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/ros2_view.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

using namespace std::chrono_literals;

const bool kLoopback = use_loopback_dds();

//! Polls `done` every 50 ms until it holds or `limit` passes.
bool poll_until(const std::function<bool()>& done, std::chrono::seconds limit = 30s) {
  const auto give_up = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= give_up) return false;
    std::this_thread::sleep_for(50ms);
  }
  return true;
}

//! A fusion service configuration ("tetra-1", 100 Hz, seed unit) with extra YAML lines.
struct ServiceFiles {
  TempDir dir;
  std::string config;
  explicit ServiceFiles(const std::string& extra = "") {
    Calibration cal = seed_as_built_unit();
    EXPECT_TRUE(write_calibration(dir.file("cal.yaml"), cal).ok());
    config = dir.file("fusion.yaml");
    write_file(config,
               "unit: tetra-1\ncalibration: cal.yaml\nsample_rate_hz: 100\nspeed: 1\n"
               "max_latency_s: 0.05\nhealth_period_s: 0.2\n" +
                   extra);
  }
};

//! 9 s of orbit at 100 Hz, 10 times faster than real time, a 1 Hz attitude reference, gyro 2 stuck from 4 s.
std::string sim_args(dds_domainid_t domain, int wait_readers, const std::string& extra = "") {
  return "sim orbit --dds --dds-unit tetra-1 --domain " + std::to_string(domain) +
         " --rate-hz 100 --minutes 0.15 --reference-hz 1 --speed 10 --fault gyro=2,kind=stuck,at=4 "
         "--wait-readers " +
         std::to_string(wait_readers) + " " + extra;
}

//! The simulator's "epochs published: N".
int epochs_published(const std::string& sim_out) {
  const auto at = sim_out.find("epochs published: ");
  return at == std::string::npos ? -1 : std::stoi(sim_out.substr(at + 18));
}

//! Samples taken from one reader, counted.
template <class T>
struct Counted {
  std::optional<dds::Reader<T>> reader;
  int count = 0;
  void drain() {
    (void)reader->take([&](const T&, const dds_sample_info_t&) { ++count; });
  }
};

template <class T>
Counted<T> counted_reader(const dds::Participant& p, const dds::Topic& topic, dds::DataRepresentation only) {
  dds::Qos qos;
  qos.reliable().volatile_durability().keep_all().data_representation(only);  // accepts this one only
  auto reader = dds::Reader<T>::create(p, topic, qos);
  EXPECT_TRUE(reader.ok()) << (reader ? "" : reader.error().message);
  Counted<T> out;
  if (reader) out.reader.emplace(std::move(reader).value());
  return out;
}

// Every topic is @final, so a reader restricted to one representation can be created for each; the
// processes' writers send the representation `--data-representation` names, and the reader receives.
void every_topic_readable(dds::DataRepresentation representation, dds_domainid_t domain) {
  const std::string flag = representation == dds::DataRepresentation::kXcdr1 ? "--data-representation xcdr1"
                                                                             : "--data-representation xcdr2";
  ServiceFiles files;
  TetraProcess fusion(
      {"fusion", "--config", files.config, "--domain", std::to_string(domain), "--data-representation",
       representation == dds::DataRepresentation::kXcdr1 ? "xcdr1" : "xcdr2"},
      files.dir.file("fusion.log"));
  auto participant = dds::Participant::create(domain);
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  auto topics = dds::Topics::create(*participant);
  ASSERT_TRUE(topics.ok()) << topics.error().message;
  auto gyro = counted_reader<tetra_GyroSample>(*participant, topics->gyro_sample, representation);
  auto reference = counted_reader<tetra_AttitudeReference>(*participant, topics->reference, representation);
  auto attitude = counted_reader<tetra_Attitude>(*participant, topics->attitude, representation);
  auto health = counted_reader<tetra_Health>(*participant, topics->health, representation);
  auto event = counted_reader<tetra_FdiEvent2>(*participant, topics->event, representation);
  auto command = counted_reader<tetra_Command>(*participant, topics->command, representation);
  ASSERT_TRUE(gyro.reader && reference.reader && attitude.reader && health.reader && event.reader &&
              command.reader);

  // Two GyroSample readers: the service's and this test's.
  const auto sim = run_tetra(sim_args(domain, 2, flag));
  ASSERT_EQ(sim.exit_status, 0) << sim.err << sim.out << read_file(files.dir.file("fusion.log"));
  const auto drain_all = [&] {
    gyro.drain();
    reference.drain();
    attitude.drain();
    health.drain();
    event.drain();
    command.drain();
  };
  // `tetra command` writes once a Command reader has matched — this test's or the service's, whichever
  // it discovers first — and then waits for the service's acknowledgement. Only the Command sample this
  // test's reader receives matters here, so the exit status (1 when the service was not the first reader
  // matched) is not checked; it is sent again until this reader has one.
  for (int attempt = 0; attempt < 10 && command.count == 0; ++attempt) {
    (void)run_tetra("command --unit tetra-1 reinstate 2 --timeout 2 --domain " + std::to_string(domain) +
                    " " + flag);
    poll_until(
        [&] {
          command.drain();
          return command.count > 0;
        },
        2s);
  }
  EXPECT_TRUE(poll_until([&] {
    drain_all();
    return gyro.count > 0 && reference.count > 0 && attitude.count > 0 && health.count > 0 &&
           event.count > 0 && command.count > 0;
  })) << "GyroSample "
      << gyro.count << ", AttitudeReference " << reference.count << ", Attitude " << attitude.count
      << ", Health " << health.count << ", FdiEvent " << event.count << ", Command " << command.count;
  // Every sample of the 4 gyros delivered (reliable writer, keep-all reader).
  EXPECT_EQ(gyro.count, 4 * epochs_published(sim.out)) << sim.out;
  EXPECT_EQ(fusion.signal_and_wait(SIGTERM), 0);
}

TEST(DdsInterop, EveryTopicReadableByAnXcdr1OnlyReader) {
  every_topic_readable(dds::DataRepresentation::kXcdr1, 213);
}

TEST(DdsInterop, EveryTopicReadableByAnXcdr2OnlyReader) {
  every_topic_readable(dds::DataRepresentation::kXcdr2, 214);
}

// --- ROS 2 view ---------------------------------------------------------------------------------

struct RosAttitude {
  std::int64_t stamp_ns;
  std::array<double, 4> xyzw;
  std::string frame_id;
};
struct RosStatus {
  int level;
  std::string name, message, hardware_id;
};

std::int64_t stamp_of(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<std::int64_t>(t.sec) * 1'000'000'000 + t.nanosec;
}

TEST(DdsInterop, Ros2ViewReadByPlainReadersWithRosTypeNamesTopicsAndQos) {
  const dds_domainid_t domain = 215;
  ServiceFiles files("ros2:\n  enabled: true\n");
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", std::to_string(domain)},
                      files.dir.file("fusion.log"));
  auto participant = dds::Participant::create(domain);
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  // What a ROS 2 subscription creates: ROS type names (idl/ros2.idl), rt/ topic names, ROS 2's default
  // QoS (reliable, volatile, keep-last) in XCDR1 only; a deeper history so the test misses nothing.
  auto make = [&](const dds_topic_descriptor_t* desc, const std::string& name) {
    auto topic = dds::Topic::create(*participant, desc, name, dds::ros2_qos());
    EXPECT_TRUE(topic.ok()) << topic.error().message;
    return std::move(topic).value();
  };
  const auto att_topic = make(&geometry_msgs_msg_dds__QuaternionStamped__desc, "rt/tetra/tetra_1/attitude");
  const auto imu_topic = make(&sensor_msgs_msg_dds__Imu__desc, "rt/tetra/tetra_1/imu");
  const auto diag_topic = make(&diagnostic_msgs_msg_dds__DiagnosticArray__desc, "rt/diagnostics");
  auto topics = dds::Topics::create(*participant);
  ASSERT_TRUE(topics.ok());
  dds::Qos deep = dds::ros2_qos();
  deep.keep_last(100000);
  auto ros_att =
      dds::Reader<geometry_msgs_msg_dds__QuaternionStamped_>::create(*participant, att_topic, deep);
  auto ros_imu = dds::Reader<sensor_msgs_msg_dds__Imu_>::create(*participant, imu_topic, deep);
  auto ros_diag =
      dds::Reader<diagnostic_msgs_msg_dds__DiagnosticArray_>::create(*participant, diag_topic, deep);
  dds::Qos tetra_deep;
  tetra_deep.reliable().volatile_durability().keep_last(100000);
  auto tetra_att = dds::Reader<tetra_Attitude>::create(*participant, topics->attitude, tetra_deep);
  ASSERT_TRUE(ros_att.ok() && ros_imu.ok() && ros_diag.ok() && tetra_att.ok());

  const auto sim = run_tetra(sim_args(domain, 1));
  ASSERT_EQ(sim.exit_status, 0) << sim.err << sim.out << read_file(files.dir.file("fusion.log"));

  std::map<std::int64_t, std::array<double, 4>> tetra_wxyz;  // by stamp
  std::vector<RosAttitude> attitudes;
  std::vector<sensor_msgs_msg_dds__Imu_> imus;  // plain numbers only (frame ids checked on the way in)
  std::vector<std::vector<RosStatus>> diagnostics;
  int imu_frames_ok = 0;
  const auto drain = [&] {
    (void)tetra_att->take([&](const tetra_Attitude& m, const dds_sample_info_t&) {
      tetra_wxyz[m.stamp_ns] = {m.q_RB[0], m.q_RB[1], m.q_RB[2], m.q_RB[3]};
    });
    (void)ros_att->take([&](const geometry_msgs_msg_dds__QuaternionStamped_& m, const dds_sample_info_t&) {
      attitudes.push_back({stamp_of(m.header.stamp),
                           {m.quaternion.x, m.quaternion.y, m.quaternion.z, m.quaternion.w},
                           m.header.frame_id});
    });
    (void)ros_imu->take([&](const sensor_msgs_msg_dds__Imu_& m, const dds_sample_info_t&) {
      if (std::string(m.header.frame_id) == "tetra_1_body") ++imu_frames_ok;
      imus.push_back(m);
      imus.back().header.frame_id = nullptr;
    });
    (void)ros_diag->take([&](const diagnostic_msgs_msg_dds__DiagnosticArray_& m, const dds_sample_info_t&) {
      std::vector<RosStatus> statuses;
      for (std::uint32_t i = 0; i < m.status._length; ++i) {
        const auto& s = m.status._buffer[i];
        statuses.push_back({s.level, s.name, s.message, s.hardware_id});
      }
      diagnostics.push_back(std::move(statuses));
    });
  };
  // About 900 epochs. Attitude is keep-last 1 at the writer, so a reader on this loaded 2-core machine may
  // skip some (the end-to-end tests allow 5 %); 90 % must arrive on each topic.
  const std::size_t epochs = static_cast<std::size_t>(epochs_published(sim.out));
  ASSERT_GT(epochs, 800U) << sim.out;
  const std::size_t enough = epochs * 9 / 10;
  EXPECT_TRUE(poll_until([&] {
    drain();
    return attitudes.size() >= enough && imus.size() >= enough && tetra_wxyz.size() >= enough &&
           diagnostics.size() >= 2;
  })) << attitudes.size()
      << " QuaternionStamped, " << imus.size() << " Imu, " << diagnostics.size() << " DiagnosticArray";

  // ROS's x, y, z, w of tetra's w, x, y, z, at the same stamp; the frame the quaternion points into.
  int compared = 0;
  for (const auto& a : attitudes) {
    EXPECT_EQ(a.frame_id, "tetra_1_reference");
    const auto it = tetra_wxyz.find(a.stamp_ns);
    if (it == tetra_wxyz.end()) continue;
    const auto& q = it->second;
    EXPECT_EQ(a.xyzw[0], q[1]);
    EXPECT_EQ(a.xyzw[1], q[2]);
    EXPECT_EQ(a.xyzw[2], q[3]);
    EXPECT_EQ(a.xyzw[3], q[0]);
    ++compared;
  }
  EXPECT_GE(static_cast<std::size_t>(compared), epochs * 8 / 10);  // both sides of a stamp received
  ASSERT_FALSE(imus.empty());
  EXPECT_GT(imus.back().orientation_covariance[0], 0.0);  // grows as the rate is integrated
  // Imu: the body frame; covariances present for orientation and rate, "not measured" (-1) for acceleration.
  EXPECT_EQ(imu_frames_ok, static_cast<int>(imus.size()));
  for (const auto& m : imus) {
    EXPECT_GE(m.orientation_covariance[0], 0.0);  // 0 at the start: the initial attitude is given exactly
    EXPECT_GT(m.angular_velocity_covariance[0], 0.0);
    EXPECT_EQ(m.angular_velocity_covariance[1], m.angular_velocity_covariance[3]);  // symmetric
    EXPECT_EQ(m.linear_acceleration_covariance[0], -1.0);
  }
  // Diagnostics: one status for the unit and one per gyro. The run goes NOMINAL (unit OK), then gyro 2
  // stuck from 4 s is excluded (gyro ERROR, unit DEGRADED: WARN); before the first samples and after the
  // last the unit is LOST (ERROR).
  ASSERT_FALSE(diagnostics.empty());
  ASSERT_EQ(diagnostics.front().size(), 5U);
  EXPECT_EQ(diagnostics.front()[0].name, "tetra/tetra_1: fusion");
  EXPECT_EQ(diagnostics.front()[0].hardware_id, "tetra-1");
  EXPECT_EQ(diagnostics.front()[2].name, "tetra/tetra_1: gyro 2");
  const auto seen = [&](int unit_level, int gyro2_level) {
    return std::any_of(diagnostics.begin(), diagnostics.end(), [&](const std::vector<RosStatus>& d) {
      return d.size() == 5 && d[0].level == unit_level && d[2].level == gyro2_level;
    });
  };
  EXPECT_TRUE(seen(0, 0)) << "never NOMINAL";
  EXPECT_TRUE(seen(1, 2)) << "never DEGRADED with gyro 2 excluded";
  EXPECT_EQ(fusion.signal_and_wait(SIGTERM), 0);
}

}  // namespace
}  // namespace tetra::test
