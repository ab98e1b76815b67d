// The fusion service as a library (docs/dds.md): started in a thread of this process on a private
// domain, fed simulated gyro samples over DDS, its Attitude checked against the simulator's truth,
// then stopped with request_stop() — no process, no signal. Waits are on DDS conditions, each with a
// generous upper bound that only turns a hang into a failure; nothing asserts on elapsed time.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <thread>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/json.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/service/fusion_service.hpp"
#include "tetra/sim/scenario.hpp"
#include "tetra/sim/simulator.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

using namespace std::chrono_literals;

const bool kLoopback = use_loopback_dds();
constexpr dds_domainid_t kDomain = 167;
constexpr dds_domainid_t kSilenceDomain = 188;  //!< the silence test's own (187 is bench/ground_latency.py's)
constexpr dds_domainid_t kCrowdDomain = 189;    //!< the crowded-out references' test's own
constexpr std::int64_t kWaitLimit_ns = 20'000'000'000;  //!< [ns] only turns a hang into a failure

//! The static scenario's unit for 3 s at 100 Hz, and the service set up for it (its files in `dir`).
struct Rig {
  TempDir dir;
  sim::Simulator simulator;
  sim::SimEpoch first;

  static sim::Simulator make_simulator() {
    auto scenario = sim::builtin_scenario("static");
    EXPECT_TRUE(scenario.ok());
    scenario->duration_s = 3.0;
    scenario->rate_hz = 100.0;
    sim::SimOptions options;
    options.seed = 7;
    return std::move(sim::Simulator::create(*scenario, options)).value();
  }
  Rig() : simulator(make_simulator()) {
    EXPECT_TRUE(simulator.next(first));
    simulator.reset();
  }

  //! The service (not movable: it owns a mutex), on the heap.
  Result<std::unique_ptr<service::FusionService>> make_service() {
    EXPECT_TRUE(write_calibration(dir.file("cal.yaml"), simulator.scenario().unit).ok());
    const auto q = to_wxyz(first.truth_q_RB);
    std::string unit;
    append_json_string(unit, simulator.scenario().unit.unit);
    std::string q_text;
    for (int i = 0; i < 4; ++i) {
      q_text += (i ? ", " : "");
      append_json_number(q_text, q[static_cast<std::size_t>(i)]);
    }
    write_file(dir.file("fusion.yaml"),
               "unit: " + unit +
                   "\ncalibration: cal.yaml\nsample_rate_hz: 100\nmax_latency_s: 0.05\n"
                   "health_period_s: 0.2\npipeline:\n  initial_q_wxyz: [" +
                   q_text + "]\n  sample_period_s: 0.01\n");
    auto config = service::read_fusion_config(dir.file("fusion.yaml"));
    if (!config) return config.error();
    auto pipeline = fdi::Pipeline::create(config->calibration, config->pipeline);
    if (!pipeline) return pipeline.error();
    auto assembler = service::EpochAssembler::create(config->assembler(pipeline->gyro_count()));
    if (!assembler) return assembler.error();
    return std::make_unique<service::FusionService>(std::move(config).value(), std::move(pipeline).value(),
                                                    std::move(assembler).value());
  }
};

//! The sensor's and the ground's side: GyroSample writer, Health and Attitude readers.
struct Peer {
  dds::Session session;
  dds::Writer<tetra_GyroSample> gyro;
  dds::Reader<tetra_Health> health;
  dds::Reader<tetra_Attitude> attitude;

  static Peer open() {
    auto session = std::move(dds::Session::open(kDomain)).value();
    // The deadline the service requests: 3 periods of its 100 Hz.
    auto gyro = std::move(session.writer<tetra_GyroSample>(dds::gyro_sample_qos(10ms))).value();
    auto health = std::move(session.reader<tetra_Health>(dds::health_qos())).value();
    dds::Qos deep;
    deep.reliable().volatile_durability().keep_last(100000);
    auto attitude = std::move(session.reader<tetra_Attitude>(deep)).value();
    EXPECT_TRUE(session.watch_data(health.handle(), 1).ok());
    EXPECT_TRUE(session.watch_data(attitude.handle(), 2).ok());
    return Peer{std::move(session), std::move(gyro), std::move(health), std::move(attitude)};
  }
  //! Waits (on the waitset) until `done()` holds after `drain()`; false when the limit passes.
  template <class Drain, class Done>
  bool wait_until(Drain&& drain, Done&& done) {
    const std::int64_t give_up = dds::monotonic_ns() + kWaitLimit_ns;
    std::vector<std::intptr_t> triggered;
    for (;;) {
      drain();
      if (done()) return true;
      const std::int64_t now = dds::monotonic_ns();
      if (now >= give_up) return false;
      EXPECT_TRUE(session.wait(std::chrono::nanoseconds(give_up - now), triggered).ok());
    }
  }
};

TEST(FusionServiceLibrary, RunsInAThreadFusesSamplesFromDdsAndStopsOnRequest) {
  ASSERT_TRUE(kLoopback);
  Rig rig;
  auto service = rig.make_service();
  ASSERT_TRUE(service.ok()) << service.error().message;
  ASSERT_TRUE((*service)->open(kDomain).ok());
  Status run_status = ok_status();
  std::thread thread([&] { run_status = (*service)->run(); });

  Peer peer = Peer::open();
  const std::string unit = rig.simulator.scenario().unit.unit;
  // The service hears our writer (its Health says so) before the first sample: none is lost.
  bool hears = false;
  ASSERT_TRUE(peer.wait_until(
      [&] {
        (void)peer.health.take([&](const tetra_Health& h, const dds_sample_info_t&) {
          hears = hears || (dds::from_wire(h.unit) == unit && h.gyro_writers > 0);
        });
      },
      [&] { return hears; }));

  // Publish every epoch (2 ms apart: faster than the 100 Hz the service expects, slower than its
  // 30 ms deadline), keeping the truth to score the attitudes against.
  std::map<std::int64_t, Quaternion> truth;
  tetra_GyroSample sample{};
  ASSERT_TRUE(dds::copy_bounded(sample.unit, unit, "unit").ok());
  sim::SimEpoch epoch;
  std::uint64_t k = 0;
  while (rig.simulator.next(epoch)) {
    truth[epoch.stamp_ns] = epoch.truth_q_RB;
    ++k;
    for (std::size_t g = 1; g <= epoch.present.size(); ++g) {
      if (epoch.present[g - 1] == 0) continue;
      sample.gyro = static_cast<std::uint16_t>(g);
      sample.seq = k;
      sample.stamp_ns = epoch.stamp_ns;
      sample.raw = epoch.raw_V[g - 1];
      ASSERT_TRUE(peer.gyro.write(sample).ok());
    }
    std::this_thread::sleep_for(2ms);
  }
  const std::int64_t last_stamp = epoch.stamp_ns;

  // Attitude out: the last epoch's arrives, and every one received is the truth within 50 arcsec. The
  // static unit's truth is fixed in R, while the service, not told its latitude, integrates the Earth's
  // rate too: at most 15.04 arcsec/s × 3 s = 45.1 arcsec, plus 5 arcsec for the gyros' noise over 3 s.
  // A wrong frame, sign or scale is degrees off.
  std::size_t received = 0;
  double worst_arcsec = 0.0;
  bool last_seen = false;
  ASSERT_TRUE(peer.wait_until(
      [&] {
        (void)peer.attitude.take([&](const tetra_Attitude& m, const dds_sample_info_t&) {
          const auto estimate = dds::from_wire(m);
          const auto it = truth.find(estimate.stamp_ns);
          ASSERT_NE(it, truth.end()) << "an attitude for an epoch never published";
          worst_arcsec =
              std::max(worst_arcsec, angle_between(estimate.q_RB, it->second) * kRadToDeg * 3600.0);
          ++received;
          last_seen = last_seen || estimate.stamp_ns == last_stamp;
        });
      },
      [&] { return last_seen; }));
  // The Attitude writer keeps only its latest sample (docs/interfaces.md §4), so a reader may miss one
  // under load; half is far below what loopback delivers and far above a service that stalls.
  EXPECT_GT(received, truth.size() / 2) << "most epochs fused";
  EXPECT_LT(worst_arcsec, 50.0);

  (*service)->request_stop();
  thread.join();
  EXPECT_TRUE(run_status.ok()) << run_status.error().message;
}

// Every gyro silent: counted in Health each time; a `lost` event only once the silence has lasted
// kMinOutageReported_s (2 s), then a `cleared`; before any epoch nothing at all (the service waits).
// The brief outage is 0.2 s, ten times below the 2 s: a margin no scheduling delay of the publishing
// loop comes near; the long one is 3 s, 1 s above it.
TEST(FusionServiceLibrary, SilenceOfEveryGyroIsReportedWithHysteresisNeverBeforeTheFirstEpoch) {
  ASSERT_TRUE(kLoopback);
  Rig rig;
  auto service = rig.make_service();
  ASSERT_TRUE(service.ok()) << service.error().message;
  ASSERT_TRUE((*service)->open(kSilenceDomain).ok());
  Status run_status = ok_status();
  std::thread thread([&] { run_status = (*service)->run(); });
  auto session = std::move(dds::Session::open(kSilenceDomain)).value();
  auto gyro = std::move(session.writer<tetra_GyroSample>(dds::gyro_sample_qos(10ms))).value();
  auto events = std::move(session.reader<tetra_FdiEvent2>(dds::event_qos())).value();
  auto health = std::move(session.reader<tetra_Health>(dds::health_qos())).value();
  std::vector<dds::EventView> seen;
  std::uint64_t silences = 0;
  const auto drain = [&] {
    (void)events.take(
        [&](const tetra_FdiEvent2& e, const dds_sample_info_t&) { seen.push_back(dds::from_wire(e)); });
    (void)health.take(
        [&](const tetra_Health& h, const dds_sample_info_t&) { silences = h.counters.unit_silences; });
  };
  std::this_thread::sleep_for(2500ms);  // no gyro heard yet: waiting, neither lost nor counted
  drain();
  EXPECT_TRUE(seen.empty());
  EXPECT_EQ(silences, 0U);

  const std::string unit = rig.simulator.scenario().unit.unit;
  tetra_GyroSample sample{};
  ASSERT_TRUE(dds::copy_bounded(sample.unit, unit, "unit").ok());
  std::set<std::int64_t> stamps;
  sim::SimEpoch epoch;
  std::uint64_t k = 0;
  const auto publish = [&](int epochs) {
    for (int i = 0; i < epochs && rig.simulator.next(epoch); ++i) {
      stamps.insert(epoch.stamp_ns);
      ++k;
      for (std::size_t g = 1; g <= epoch.present.size(); ++g) {
        sample.gyro = static_cast<std::uint16_t>(g);
        sample.seq = k;
        sample.stamp_ns = epoch.stamp_ns;
        sample.raw = epoch.raw_V[g - 1];
        ASSERT_TRUE(gyro.write(sample).ok());
      }
      std::this_thread::sleep_for(2ms);
    }
  };
  publish(50);
  std::this_thread::sleep_for(200ms);  // brief: counted, no event
  publish(50);
  std::this_thread::sleep_for(3000ms);  // long: lost, then cleared when samples are back
  publish(50);
  const std::int64_t give_up = dds::monotonic_ns() + kWaitLimit_ns;
  while (dds::monotonic_ns() < give_up && (seen.size() < 2 || silences < 2)) {
    std::this_thread::sleep_for(50ms);
    drain();
  }
  ASSERT_EQ(seen.size(), 2U);
  EXPECT_EQ(seen[0].event.type, fdi::EventType::kLost);
  EXPECT_EQ(seen[1].event.type, fdi::EventType::kCleared);
  EXPECT_EQ(stamps.count(seen[0].event.stamp_ns), 1U) << "a sensor time the unit never had";
  EXPECT_EQ(stamps.count(seen[1].event.stamp_ns), 1U) << "a sensor time the unit never had";
  // The brief and the long silence, a third once the last samples have gone silent, and more on a loaded
  // machine where the publishing loop stalls past the 30 ms deadline: each counted, none an event.
  EXPECT_GE(silences, 2U);
  (*service)->request_stop();
  thread.join();
  EXPECT_TRUE(run_status.ok()) << run_status.error().message;
}

// More late references than wait for an epoch (a tracker's burst while the gyros pause): the oldest beyond
// service::EpochAssembler::kMaxLateReferences give way, and that is said — Health's references_too_late
// counts them (not samples_late) and one `reference_late` event reports the run. Before, only samples_late
// moved.
TEST(FusionServiceLibrary, LateReferencesCrowdedOutAreCountedAsTooLateAndReportedOnce) {
  ASSERT_TRUE(kLoopback);
  Rig rig;
  auto service = rig.make_service();
  ASSERT_TRUE(service.ok()) << service.error().message;
  ASSERT_TRUE((*service)->open(kCrowdDomain).ok());
  Status run_status = ok_status();
  std::thread thread([&] { run_status = (*service)->run(); });
  auto session = std::move(dds::Session::open(kCrowdDomain)).value();
  auto gyro = std::move(session.writer<tetra_GyroSample>(dds::gyro_sample_qos(10ms))).value();
  auto reference = std::move(session.writer<tetra_AttitudeReference>(dds::reference_qos())).value();
  auto events = std::move(session.reader<tetra_FdiEvent2>(dds::event_qos())).value();
  auto health = std::move(session.reader<tetra_Health>(dds::health_qos())).value();
  std::vector<dds::EventView> seen;
  std::optional<dds::HealthView> last;
  const auto drain = [&] {
    (void)events.take(
        [&](const tetra_FdiEvent2& e, const dds_sample_info_t&) { seen.push_back(dds::from_wire(e)); });
    (void)health.take([&](const tetra_Health& h, const dds_sample_info_t&) { last = dds::from_wire(h); });
  };
  const auto wait_for = [&](const std::function<bool()>& done) {
    const std::int64_t give_up = dds::monotonic_ns() + kWaitLimit_ns;
    for (drain(); !done() && dds::monotonic_ns() < give_up; drain()) std::this_thread::sleep_for(20ms);
    return done();
  };
  ASSERT_TRUE(wait_for([&] {
    return last && last->gyro_writers > 0 && reference.matched_readers().ok() &&
           *reference.matched_readers() > 0;
  }));

  const std::string unit = rig.simulator.scenario().unit.unit;
  tetra_GyroSample sample{};
  ASSERT_TRUE(dds::copy_bounded(sample.unit, unit, "unit").ok());
  std::vector<sim::SimEpoch> published;
  std::uint64_t k = 0;
  const auto publish = [&](int epochs) {
    sim::SimEpoch epoch;
    for (int i = 0; i < epochs && rig.simulator.next(epoch); ++i) {
      published.push_back(epoch);
      ++k;
      for (std::size_t g = 1; g <= epoch.present.size(); ++g) {
        sample.gyro = static_cast<std::uint16_t>(g);
        sample.seq = k;
        sample.stamp_ns = epoch.stamp_ns;
        sample.raw = epoch.raw_V[g - 1];
        ASSERT_TRUE(gyro.write(sample).ok());
      }
      std::this_thread::sleep_for(2ms);
    }
  };
  publish(20);
  ASSERT_TRUE(wait_for([&] { return last && last->health.counters.epochs_accepted >= 20; }));
  // 12 references for epochs 1..12, all fused already, while no epoch comes: 4 more than may wait.
  constexpr std::size_t kSent = service::EpochAssembler::kMaxLateReferences + 4;
  tetra_AttitudeReference ref{};
  ASSERT_TRUE(dds::copy_bounded(ref.unit, unit, "unit").ok());
  for (std::size_t i = 1; i <= kSent; ++i) {
    ref.stamp_ns = published[i].stamp_ns;
    const auto q = to_wxyz(published[i].truth_q_RB);
    for (std::size_t c = 0; c < 4; ++c) ref.q_RB[c] = q[c];
    ASSERT_TRUE(reference.write(ref).ok());
    std::this_thread::sleep_for(5ms);  // taken one by one (the reader keeps 8)
  }
  publish(5);  // 5 of the 8 waiting go on, one an epoch
  const auto crowded_events = [&] {
    return std::count_if(seen.begin(), seen.end(), [](const dds::EventView& e) {
      return e.event.type == fdi::EventType::kReferenceLate &&
             e.event.detail.find("crowded out") != std::string::npos;
    });
  };
  ASSERT_TRUE(wait_for([&] {
    return last && last->health.counters.epochs_accepted >= 25 && crowded_events() >= 1 &&
           last->health.counters.reference_delayed >= 5;
  })) << "references_too_late "
      << (last ? last->health.counters.reference_too_late : 0);
  EXPECT_EQ(last->health.counters.reference_too_late, kSent - service::EpochAssembler::kMaxLateReferences);
  EXPECT_EQ(last->counters.samples_late, 0U);
  EXPECT_EQ(crowded_events(), 1);  // one run, one event
  (*service)->request_stop();
  thread.join();
  EXPECT_TRUE(run_status.ok()) << run_status.error().message;
}

TEST(FusionServiceLibrary, AStopRequestedBeforeRunEndsItAtOnce) {
  ASSERT_TRUE(kLoopback);
  Rig rig;
  auto service = rig.make_service();
  ASSERT_TRUE(service.ok()) << service.error().message;
  ASSERT_TRUE((*service)->open(kDomain + 1).ok());
  (*service)->request_stop();
  EXPECT_TRUE((*service)->run().ok());
}

}  // namespace
}  // namespace tetra::test
