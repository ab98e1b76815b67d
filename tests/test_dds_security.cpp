// DDS Security: the demo PKI of scripts/security/make_pki.sh (units sec-1 and sec-2), its
// roles, and the promises — an unauthenticated participant sees nothing and injects nothing; a
// sensor identity cannot write Command; an identity without the grant cannot write GyroSample; the
// sensor of one unit cannot write GyroSample for another. Each test also shows the positive case, so
// a test cannot pass merely because nothing works.
// Real Cyclone DDS on loopback, separate processes, one domain per test (171–174); processes are
// killed by the test. Waits have generous upper bounds that only turn a hang into a failure.

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/service/security_profile.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

using namespace std::chrono_literals;

const bool kLoopback = use_loopback_dds();

//! The demo PKI, made once for the whole suite (about 2 s of openssl).
class DdsSecurity : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    pki_ = new TempDir();
    const auto made = run_shell("bash " + source_path("scripts/security/make_pki.sh") + " " +
                                pki_->path().string() + " 0-230 sec-1 sec-2");
    ASSERT_EQ(made.exit_status, 0) << made.err << made.out;
  }
  static void TearDownTestSuite() {
    delete pki_;
    pki_ = nullptr;
  }
  void TearDown() override { dds::set_security_profile(std::nullopt); }

  static std::string profile(const std::string& role) { return pki_->file(role + ".yaml"); }
  static service::SecurityProfile load(const std::string& role) {
    auto p = service::read_security_profile(profile(role));
    EXPECT_TRUE(p.ok()) << p.error().message;
    return p.value();
  }
  //! Whether this process's identity may create a GyroSample writer for `unit` on `domain`.
  static Status gyro_writer_for(dds_domainid_t domain, const std::string& unit) {
    auto participant = dds::Participant::create(domain, unit);
    if (!participant) return participant.error();
    auto topics = dds::Topics::create(*participant);
    if (!topics) return topics.error();
    auto writer =
        dds::Writer<tetra_GyroSample>::create(*participant, topics->gyro_sample, dds::gyro_sample_qos());
    if (!writer) return writer.error();
    return ok_status();
  }
  //! A service configuration (calibration of the simulated unit, the fusion identity) in `dir`.
  static std::string service_config(const TempDir& dir, const std::string& unit) {
    Calibration cal = seed_as_built_unit();
    cal.unit = unit;
    EXPECT_TRUE(write_calibration(dir.file("cal.yaml"), cal).ok());
    write_file(dir.file("fusion.yaml"), "unit: " + unit +
                                            "\ncalibration: cal.yaml\nsample_rate_hz: 50\nspeed: 1\n"
                                            "max_latency_s: 0.05\nhealth_period_s: 0.2\nsecurity: " +
                                            profile("fusion") + "\n");
    return dir.file("fusion.yaml");
  }

  static TempDir* pki_;
};
TempDir* DdsSecurity::pki_ = nullptr;

template <class T>
int count_taken(const dds::Reader<T>& reader) {
  int n = 0;
  (void)reader.take([&](const T&, const dds_sample_info_t&) { ++n; });
  return n;
}

TEST_F(DdsSecurity, UnauthenticatedParticipantSeesAndInjectsNothing) {
  const dds_domainid_t domain = 171;
  TempDir dir;
  TetraProcess fusion(
      {"fusion", "--config", service_config(dir, "sec-1"), "--domain", std::to_string(domain)},
      dir.file("fusion.log"));
  // The secured sensor: 12 s of an orbit at 50 Hz in real time.
  TetraProcess sim({"sim", "orbit", "--dds", "--dds-unit", "sec-1", "--domain", std::to_string(domain),
                    "--rate-hz", "50", "--minutes", "0.2", "--reference-hz", "0", "--security",
                    profile("sensor-sec-1"), "--wait-timeout", "30"},
                   dir.file("sim.log"));

  // The eavesdropper: no credentials, a reader on each of the six topics, for 3 s of the secured run.
  {
    auto participant = dds::Participant::create(domain);
    ASSERT_TRUE(participant.ok()) << participant.error().message;
    auto topics = dds::Topics::create(*participant);
    ASSERT_TRUE(topics.ok()) << topics.error().message;
    auto health = dds::Reader<tetra_Health>::create(*participant, topics->health, dds::health_qos());
    auto attitude = dds::Reader<tetra_Attitude>::create(*participant, topics->attitude, dds::attitude_qos());
    auto events = dds::Reader<tetra_FdiEvent2>::create(*participant, topics->event, dds::event_qos());
    auto samples =
        dds::Reader<tetra_GyroSample>::create(*participant, topics->gyro_sample, dds::gyro_sample_qos());
    auto references =
        dds::Reader<tetra_AttitudeReference>::create(*participant, topics->reference, dds::reference_qos());
    auto commands = dds::Reader<tetra_Command>::create(*participant, topics->command, dds::command_qos());
    ASSERT_TRUE(health.ok() && attitude.ok() && events.ok() && samples.ok() && references.ok() &&
                commands.ok());
    int seen = 0;
    for (int k = 0; k < 30; ++k) {
      seen += count_taken(*health) + count_taken(*attitude) + count_taken(*events) + count_taken(*samples) +
              count_taken(*references) + count_taken(*commands);
      std::this_thread::sleep_for(100ms);
    }
    EXPECT_EQ(seen, 0) << "the unauthenticated participant received samples";
    for (dds_entity_t reader : {health->handle(), attitude->handle(), events->handle(), samples->handle(),
                                references->handle(), commands->handle()}) {
      dds_subscription_matched_status_t matched{};
      ASSERT_EQ(dds_get_subscription_matched_status(reader, &matched), DDS_RETCODE_OK);
      EXPECT_EQ(matched.total_count, 0u) << "an unauthenticated reader matched a secured writer";
    }
  }
  // The injector: no credentials, writes a reset command and wild samples for the unit for 3 s.
  {
    auto participant = dds::Participant::create(domain);
    ASSERT_TRUE(participant.ok()) << participant.error().message;
    auto topics = dds::Topics::create(*participant);
    ASSERT_TRUE(topics.ok()) << topics.error().message;
    auto gyro_writer =
        dds::Writer<tetra_GyroSample>::create(*participant, topics->gyro_sample, dds::gyro_sample_qos());
    auto command_writer =
        dds::Writer<tetra_Command>::create(*participant, topics->command, dds::command_qos());
    ASSERT_TRUE(gyro_writer.ok() && command_writer.ok());
    tetra_Command command{};
    std::snprintf(command.unit, sizeof command.unit, "%s", "sec-1");
    command.command_id = 4242;
    command.kind = tetra_COMMAND_RESET;
    tetra_GyroSample sample{};
    std::snprintf(sample.unit, sizeof sample.unit, "%s", "sec-1");
    for (int k = 0; k < 30; ++k) {
      sample.gyro = static_cast<std::uint16_t>(1 + k % 4);
      sample.seq = 1000000U + static_cast<std::uint64_t>(k);
      sample.raw = 1.0e3;
      EXPECT_TRUE(gyro_writer->write(sample).ok());
      EXPECT_TRUE(command_writer->write(command).ok());
      std::this_thread::sleep_for(100ms);
    }
    EXPECT_EQ(gyro_writer->matched_readers().value(), 0u)
        << "a secured reader matched an unauthenticated writer";
    EXPECT_EQ(command_writer->matched_readers().value(), 0u);
  }

  // Positive control, with the ground identity: the service ran on the sensor's samples and no
  // command or wild sample reached it.
  const auto ground = run_tetra("monitor --once --jsonl --unit sec-1 --timeout 20 --domain " +
                                std::to_string(domain) + " --security " + profile("ground"));
  ASSERT_EQ(ground.exit_status, 0) << ground.err << read_file(dir.file("fusion.log"));
  EXPECT_NE(ground.out.find("\"mode\": \"NOMINAL\""), std::string::npos) << ground.out;
  EXPECT_EQ(ground.out.find("\"command_id\": 4242"), std::string::npos) << ground.out;
  EXPECT_NE(ground.out.find("\"samples_invalid\": 0,"), std::string::npos) << ground.out;
  EXPECT_EQ(ground.out.find("\"epochs_accepted\": 0,"), std::string::npos) << ground.out;
  // The ground identity may command: acknowledged by the service.
  const auto reset = run_tetra("command --unit sec-1 --timeout 20 --domain " + std::to_string(domain) +
                               " --security " + profile("ground") + " reset");
  EXPECT_EQ(reset.exit_status, 0) << reset.err << reset.out;
  EXPECT_EQ(sim.wait_exit(), 0) << read_file(dir.file("sim.log"));
  EXPECT_NE(read_file(dir.file("sim.log")).find("attitudes scored: "), std::string::npos)
      << read_file(dir.file("sim.log"));
}

TEST_F(DdsSecurity, SensorCannotWriteCommand) {
  const dds_domainid_t domain = 172;
  dds::set_security_profile(load("sensor-sec-1"));
  auto participant = dds::Participant::create(domain, "sec-1");
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  auto topics = dds::Topics::create(*participant);
  ASSERT_TRUE(topics.ok()) << topics.error().message;
  // Allowed: the sensor's own topic.
  auto gyro =
      dds::Writer<tetra_GyroSample>::create(*participant, topics->gyro_sample, dds::gyro_sample_qos());
  EXPECT_TRUE(gyro.ok()) << gyro.error().message;
  // Refused: Command.
  auto command = dds::Writer<tetra_Command>::create(*participant, topics->command, dds::command_qos());
  ASSERT_FALSE(command.ok());
  EXPECT_NE(command.error().message.find("Not Allowed By Security"), std::string::npos)
      << command.error().message;
  // The same through the command line.
  const auto cli = run_tetra("command --unit sec-1 --timeout 5 --domain " + std::to_string(domain) +
                             " --security " + profile("sensor-sec-1") + " reset");
  EXPECT_EQ(cli.exit_status, 1) << cli.err;
  EXPECT_NE(cli.err.find("Not Allowed By Security"), std::string::npos) << cli.err;
}

TEST_F(DdsSecurity, OnlySensorsWriteGyroSamples) {
  const dds_domainid_t domain = 173;
  for (const char* role : {"ground", "fusion"}) {
    dds::set_security_profile(load(role));
    auto participant = dds::Participant::create(domain);
    ASSERT_TRUE(participant.ok()) << role << ": " << participant.error().message;
    auto topics = dds::Topics::create(*participant);
    ASSERT_TRUE(topics.ok()) << topics.error().message;
    auto writer =
        dds::Writer<tetra_GyroSample>::create(*participant, topics->gyro_sample, dds::gyro_sample_qos());
    ASSERT_FALSE(writer.ok()) << role << " may write GyroSample";
    EXPECT_NE(writer.error().message.find("Not Allowed By Security"), std::string::npos)
        << role << ": " << writer.error().message;
    // Each may read the samples (positive control: the identity itself is accepted).
    auto reader =
        dds::Reader<tetra_GyroSample>::create(*participant, topics->gyro_sample, dds::gyro_sample_qos());
    EXPECT_TRUE(reader.ok()) << role << ": " << reader.error().message;
  }
  // A simulator started with the ground identity is refused.
  const auto sim = run_tetra("sim orbit --dds --dds-unit sec-1 --minutes 0.01 --wait-timeout 2 --domain " +
                             std::to_string(domain) + " --security " + profile("ground"));
  EXPECT_EQ(sim.exit_status, 1) << sim.err << sim.out;
  EXPECT_NE(sim.err.find("Not Allowed By Security"), std::string::npos) << sim.err;
}

TEST_F(DdsSecurity, SensorOfAnotherUnitCannotWriteGyroSamplesForThisUnit) {
  const dds_domainid_t domain = 174;
  // Unit sec-2's sensor may write in its own unit's partition only.
  dds::set_security_profile(load("sensor-sec-2"));
  const Status other = gyro_writer_for(domain, "sec-1");
  ASSERT_FALSE(other.ok()) << "sensor-sec-2 may write GyroSample for unit sec-1";
  EXPECT_NE(other.error().message.find("Not Allowed By Security"), std::string::npos)
      << other.error().message;
  // Positive control: the same identity writes for its own unit, in its own partition.
  const Status own_unit = gyro_writer_for(domain, "sec-2");
  EXPECT_TRUE(own_unit.ok()) << own_unit.error().message;
  EXPECT_EQ(dds::unit_partition("sec-2"), "tetra.sec-2");
  // A unit name that would be a partition pattern is refused with security.
  auto wild = dds::Participant::create(domain, "sec-*");
  ASSERT_FALSE(wild.ok());
  EXPECT_NE(wild.error().message.find("sec-*"), std::string::npos) << wild.error().message;

  // Through the command line: a simulator of unit sec-1 with sec-2's identity is refused ...
  const auto sim = run_tetra("sim orbit --dds --dds-unit sec-1 --minutes 0.01 --wait-timeout 2 --domain " +
                             std::to_string(domain) + " --security " + profile("sensor-sec-2"));
  EXPECT_EQ(sim.exit_status, 1) << sim.err << sim.out;
  EXPECT_NE(sim.err.find("Not Allowed By Security"), std::string::npos) << sim.err;

  // ... and samples keyed for sec-1 but written in sec-2's partition never reach sec-1's service.
  TempDir dir;
  TetraProcess fusion(
      {"fusion", "--config", service_config(dir, "sec-1"), "--domain", std::to_string(domain)},
      dir.file("fusion.log"));
  {
    auto participant = dds::Participant::create(domain, "sec-2");
    ASSERT_TRUE(participant.ok()) << participant.error().message;
    auto topics = dds::Topics::create(*participant);
    ASSERT_TRUE(topics.ok()) << topics.error().message;
    auto writer =
        dds::Writer<tetra_GyroSample>::create(*participant, topics->gyro_sample, dds::gyro_sample_qos());
    ASSERT_TRUE(writer.ok()) << writer.error().message;
    const Calibration cal = seed_as_built_unit();
    tetra_GyroSample sample{};
    std::snprintf(sample.unit, sizeof sample.unit, "%s", "sec-1");
    for (int k = 0; k < 60; ++k) {  // 3 s at 20 Hz
      for (int g = 1; g <= 4; ++g) {
        sample.gyro = static_cast<std::uint16_t>(g);
        sample.seq = static_cast<std::uint64_t>(k) + 1;
        sample.stamp_ns = static_cast<std::int64_t>(k + 1) * 50'000'000;
        sample.raw = cal.gyros[static_cast<std::size_t>(g - 1)].bias_V;
        EXPECT_TRUE(writer->write(sample).ok());
      }
      std::this_thread::sleep_for(50ms);
    }
    EXPECT_EQ(writer->matched_readers().value(), 0u) << "sec-1's service matched sec-2's sensor";
  }
  dds::set_security_profile(std::nullopt);
  const auto before = run_tetra("monitor --once --jsonl --unit sec-1 --timeout 20 --domain " +
                                std::to_string(domain) + " --security " + profile("ground"));
  ASSERT_EQ(before.exit_status, 0) << before.err << read_file(dir.file("fusion.log"));
  EXPECT_NE(before.out.find("\"samples_accepted\": 0,"), std::string::npos) << before.out;
  EXPECT_NE(before.out.find("\"samples_other_unit\": 0,"), std::string::npos) << before.out;
  // Positive control: sec-1's own sensor is heard.
  const auto own = run_tetra(
      "sim orbit --dds --dds-unit sec-1 --rate-hz 50 --minutes 0.05 --reference-hz 0 "
      "--wait-timeout 30 --domain " +
      std::to_string(domain) + " --security " + profile("sensor-sec-1"));
  ASSERT_EQ(own.exit_status, 0) << own.err << read_file(dir.file("fusion.log"));
  EXPECT_NE(own.out.find("attitudes scored: "), std::string::npos) << own.out << own.err;
}

}  // namespace
}  // namespace tetra::test
