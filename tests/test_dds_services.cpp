// Acceptance tests of the DDS services: real Cyclone DDS on loopback, separate processes.
// Every test uses its own domain id and kills what it starts (TetraProcess's destructor: SIGKILL).
// Waits are on DDS conditions (waitsets) or process exits, each with a generous upper bound that
// only turns a hang into a failure; nothing asserts on elapsed time.

#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "test_support.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra_process.hpp"

namespace tetra::test {
namespace {

using namespace std::chrono_literals;

// Loopback-only discovery for this process and every child it starts.
const bool kLoopback = use_loopback_dds();

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

//! The service's configuration and calibration in a temporary folder.
struct ServiceFiles {
  TempDir dir;
  std::string config;
  ServiceFiles(double rate_hz, double speed, const std::string& unit = "tetra-1",
               const std::string& gyro_dispatch = "listener") {
    Calibration cal = seed_as_built_unit();
    cal.unit = unit;
    EXPECT_TRUE(write_calibration(dir.file("cal.yaml"), cal).ok());
    config = dir.file("fusion.yaml");
    write_file(config,
               "unit: " + unit + "\ncalibration: cal.yaml\nsample_rate_hz: " + std::to_string(rate_hz) +
                   "\nspeed: " + std::to_string(speed) + "\nmax_latency_s: 0.05\nhealth_period_s: 0.2\n" +
                   "gyro_dispatch: " + gyro_dispatch + "\n");
  }
};

//! The test's own view of the domain: Health, Attitude and FdiEvent readers on a waitset.
class Observer {
 public:
  explicit Observer(dds_domainid_t domain) {
    participant_.emplace(std::move(dds::Participant::create(domain)).value());
    topics_.emplace(std::move(dds::Topics::create(*participant_)).value());
    health_.emplace(
        std::move(dds::Reader<tetra_Health>::create(*participant_, topics_->health, dds::health_qos()))
            .value());
    dds::Qos deep;
    deep.reliable().volatile_durability().keep_last(100000);
    attitude_.emplace(
        std::move(dds::Reader<tetra_Attitude>::create(*participant_, topics_->attitude, deep)).value());
    events_.emplace(
        std::move(dds::Reader<tetra_FdiEvent2>::create(*participant_, topics_->event, dds::event_qos()))
            .value());
    waitset_.emplace(std::move(dds::WaitSet::create(*participant_)).value());
    for (dds_entity_t reader : {health_->handle(), attitude_->handle(), events_->handle()}) {
      conditions_.push_back(std::move(dds::Condition::data_available(reader)).value());
      EXPECT_TRUE(waitset_->attach(conditions_.back().handle(), 1).ok());
    }
  }
  const dds::Participant& participant() const { return *participant_; }
  const dds::Topics& topics() const { return *topics_; }

  //! Takes what arrived and checks `done` after each batch, until it holds or `limit` passes.
  bool wait_until(const std::function<bool()>& done, std::chrono::seconds limit = 20s) {
    const std::int64_t give_up = now_ns() + std::chrono::nanoseconds(limit).count();
    std::vector<std::intptr_t> triggered;
    for (;;) {
      drain();
      if (done()) return true;
      const std::int64_t now = now_ns();
      if (now >= give_up) return false;
      EXPECT_TRUE(waitset_->wait(std::chrono::nanoseconds(give_up - now), triggered).ok());
    }
  }
  void drain() {
    (void)health_->take([&](const tetra_Health& m, const dds_sample_info_t&) {
      auto view = dds::from_wire(m);
      health[view.unit] = std::move(view);
    });
    (void)attitude_->take([&](const tetra_Attitude& m, const dds_sample_info_t&) {
      attitude_units[dds::from_wire(m.unit)] += 1;
      attitudes.push_back(dds::from_wire(m));
    });
    (void)events_->take(
        [&](const tetra_FdiEvent2& m, const dds_sample_info_t&) { events.push_back(dds::from_wire(m)); });
  }
  bool has_event(fdi::EventType type, std::optional<int> gyro = std::nullopt) const {
    for (const auto& e : events) {
      if (e.event.type == type && (!gyro || e.event.gyro == gyro)) return true;
    }
    return false;
  }

  std::map<std::string, dds::HealthView> health;
  std::map<std::string, int> attitude_units;
  std::vector<fdi::AttitudeEstimate> attitudes;
  std::vector<dds::EventView> events;

 private:
  std::optional<dds::Participant> participant_;
  std::optional<dds::Topics> topics_;
  std::optional<dds::Reader<tetra_Health>> health_;
  std::optional<dds::Reader<tetra_Attitude>> attitude_;
  std::optional<dds::Reader<tetra_FdiEvent2>> events_;
  std::vector<dds::Condition> conditions_;
  std::optional<dds::WaitSet> waitset_;
};

std::string d(dds_domainid_t domain) {
  return std::to_string(domain);
}

// The simulated run of the end-to-end tests: orbit motion without a reference (the service starts
// at the identity attitude, so a reference would disagree by design), 100 Hz, 30 s, stuck gyro 2
// from 10 s, 10 times faster than real time.
std::string sim_args(dds_domainid_t domain, int wait_readers) {
  return "sim orbit --dds --dds-unit tetra-1 --domain " + d(domain) +
         " --rate-hz 100 --minutes 0.5 --reference-hz 0 --speed 10 " +
         "--fault gyro=2,kind=stuck,at=10 --wait-readers " + std::to_string(wait_readers);
}

TEST(DdsServices, StuckGyroIsIsolatedAndAttitudeFlowsDegraded_LateMonitorAndCommand) {
  const dds_domainid_t domain = 161;
  // The simulator runs 10 times faster than real time; the service keeps speed 1, so its deadline
  // (3 periods = 30 ms of wall clock) leaves this loaded 2-core machine a margin.
  ServiceFiles files(100.0, 1.0);
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", d(domain)},
                      files.dir.file("fusion.log"));
  Observer observer(domain);
  const auto sim = run_tetra(sim_args(domain, 1));
  ASSERT_EQ(sim.exit_status, 0) << sim.err << sim.out << read_file(files.dir.file("fusion.log"));
  // Attitude flows at the input rate: one per epoch (3000 epochs: 30 s at 100 Hz). Attitude is
  // keep-last 1 (the latest is what matters), so a consumer that falls behind on this loaded 2-core
  // machine may skip some; at least 95 % must arrive (typically all, or all but the very first: a
  // volatile writer sends only to readers it has already discovered).
  EXPECT_NE(sim.out.find("epochs published: 3000"), std::string::npos) << sim.out;
  const auto at = sim.out.find("attitudes scored: ");
  ASSERT_NE(at, std::string::npos) << sim.out;
  EXPECT_GE(std::stoi(sim.out.substr(at + 18)), 2850) << sim.out;
  EXPECT_NE(sim.out.find("mode DEGRADED, gyros 134"), std::string::npos) << sim.out;

  // A monitor started after the fault still gets the event history (transient-local).
  const auto late = run_tetra("monitor --once --jsonl --domain " + d(domain) + " --unit tetra-1");
  ASSERT_EQ(late.exit_status, 0) << late.err;
  EXPECT_NE(late.out.find("\"event\": \"detected\""), std::string::npos) << late.out;
  EXPECT_NE(late.out.find("\"event\": \"isolated\", \"gyro\": 2, \"kind\": \"stuck\""), std::string::npos)
      << late.out;
  EXPECT_NE(late.out.find("\"event\": \"reconfigured\", \"gyros\": [1, 3, 4]"), std::string::npos)
      << late.out;
  EXPECT_NE(late.out.find("\"type\": \"health\""), std::string::npos) << late.out;

  // The operator reinstates gyro 2: obeyed and acknowledged as an event.
  const auto command = run_tetra("command --unit tetra-1 reinstate 2 --domain " + d(domain));
  ASSERT_EQ(command.exit_status, 0) << command.err;
  EXPECT_NE(command.out.find("\"event\": \"command\""), std::string::npos) << command.out;
  ASSERT_TRUE(observer.wait_until([&] {
    for (const auto& e : observer.events) {
      if (e.event.type == fdi::EventType::kCommand && e.command_id != 0) return true;
    }
    return false;
  }));
  ASSERT_TRUE(observer.wait_until([&] {
    const auto it = observer.health.find("tetra-1");
    return it != observer.health.end() && it->second.health.gyros.size() == 4 &&
           it->second.health.gyros[1].state != fdi::GyroState::kExcluded;
  })) << "gyro 2 still excluded after reinstate";
  EXPECT_EQ(fusion.signal_and_wait(SIGTERM), 0) << "clean shutdown on SIGTERM";
}

// Parses an attitude CSV (docs/interfaces.md §2.4) into rows of numbers and the mode/gyros text.
struct AttitudeRows {
  std::vector<std::array<double, 9>> numbers;
  std::vector<std::string> labels;
};
AttitudeRows read_attitude(const std::string& path) {
  AttitudeRows rows;
  std::istringstream in(read_file(path));
  std::string line;
  while (std::getline(in, line) && line.rfind("time_s", 0) != 0) {
  }  // provenance comments, then the header
  while (std::getline(in, line)) {
    std::array<double, 9> v{};
    std::istringstream cells(line);
    std::string cell;
    for (double& x : v) {
      std::getline(cells, cell, ',');
      x = std::stod(cell);
    }
    std::string rest;
    std::getline(cells, rest);
    // mode, gyros, sigma_x/y/z_deg; the bias columns after them are the filter's, which DDS Attitude does not
    // carry (a recorder writes them nan; Health has the estimates).
    std::size_t end = 0;
    for (int commas = 0; end < rest.size(); ++end) {
      if (rest[end] == ',' && ++commas == 5) break;
    }
    rows.numbers.push_back(v);
    rows.labels.push_back(rest.substr(0, end));
  }
  return rows;
}

//! Shell-like words of `text` (no quoting: the test's arguments have none).
std::vector<std::string> split_args(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

//! Events lines without the service's reports on its gyro streams (all silent / samples back).
std::string without_stream_events(const std::string& events) {
  std::istringstream in(events);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    if (line.find("all gyros silent") == std::string::npos &&
        line.find("gyro samples back") == std::string::npos)
      out += line + '\n';
  }
  return out;
}

//! The same for both ways gyro samples reach the pipeline (docs/dds.md, "Latency").
class DdsReplayEquivalence : public ::testing::TestWithParam<const char*> {};

TEST_P(DdsReplayEquivalence, ReplayOfTheRecordedLogGivesTheSameEventsAndAttitudes) {
  const bool listener = std::string(GetParam()) == "listener";
  const dds_domainid_t domain = listener ? 162 : 166;
  ServiceFiles files(100.0, 1.0, "tetra-1", GetParam());
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", d(domain)},
                      files.dir.file("fusion.log"));
  TetraProcess record(
      {"record", "--config", files.config, "--domain", d(domain), "-o", files.dir.file("rec.csv"),
       "--attitude", files.dir.file("dds_att.csv"), "--events", files.dir.file("dds_ev.jsonl"), "--commands",
       files.dir.file("dds_cmd.jsonl"), "--until-idle"},
      files.dir.file("record.log"));
  TetraProcess sim(split_args(sim_args(domain, 2)), files.dir.file("sim.log"));  // waits for both
  // An operator command somewhere in the run (where exactly does not matter: replay re-applies it
  // where the service obeyed it). Accepted before gyro 2 is isolated, refused after.
  const auto command = run_tetra("command --unit tetra-1 exclude 1 --operator test --domain " + d(domain));
  ASSERT_NE(command.out.find("\"event\": \"command\""), std::string::npos) << command.err;
  ASSERT_EQ(sim.wait_exit(), 0) << read_file(files.dir.file("sim.log"));
  ASSERT_EQ(record.wait_exit(), 0) << read_file(files.dir.file("record.log"));
  EXPECT_NE(read_file(files.dir.file("dds_cmd.jsonl")).find("\"command\":\"exclude\""), std::string::npos);
  const auto replay =
      run_tetra("replay " + files.dir.file("rec.csv") + " --calibration " + files.dir.file("cal.yaml") +
                " --attitude " + files.dir.file("replay_att.csv") + " --events " +
                files.dir.file("replay_ev.jsonl") + " --commands " + files.dir.file("dds_cmd.jsonl"));
  ASSERT_EQ(replay.exit_status, 0) << replay.err;

  // Same events, in the same order, with the same numbers (both sides format with to_json), the
  // command's acknowledgement included. The service's own events about its gyro streams (all silent
  // before the simulator starts and after it ends, back in between) have no counterpart in a log.
  const std::string dds_events = without_stream_events(read_file(files.dir.file("dds_ev.jsonl")));
  EXPECT_FALSE(dds_events.empty());
  EXPECT_NE(dds_events.find("\"event\": \"command\""), std::string::npos);
  EXPECT_EQ(dds_events, read_file(files.dir.file("replay_ev.jsonl")));
  // Same epochs, the same attitudes bit for bit: both run the same pipeline on the same doubles (the log
  // keeps every raw value and time in shortest round-trip text) and both write shortest round-trip text, so
  // the parsed numbers are equal, not merely close.
  // Attitude is keep-last 1 (the latest is what matters): the recorder may miss some under load
  // (see the end-to-end test). Every attitude it did receive must equal replay's attitude of the same
  // epoch, and it must have received at least 95 %.
  const auto a = read_attitude(files.dir.file("dds_att.csv"));
  const auto b = read_attitude(files.dir.file("replay_att.csv"));
  ASSERT_EQ(b.numbers.size(), 3000U);
  EXPECT_GE(a.numbers.size(), 2850U);
  std::map<double, std::size_t> replay_row;  // time_s → row (times are exact: same text, same parse)
  for (std::size_t k = 0; k < b.numbers.size(); ++k) replay_row[b.numbers[k][0]] = k;
  for (std::size_t k = 0; k < a.numbers.size(); ++k) {
    const auto it = replay_row.find(a.numbers[k][0]);
    ASSERT_NE(it, replay_row.end()) << "an epoch replay did not see: t = " << a.numbers[k][0];
    for (std::size_t j = 1; j < 9; ++j) {
      ASSERT_EQ(a.numbers[k][j], b.numbers[it->second][j]) << "t = " << a.numbers[k][0] << " column " << j;
    }
    ASSERT_EQ(a.labels[k], b.labels[it->second]) << "t = " << a.numbers[k][0];
  }
}

INSTANTIATE_TEST_SUITE_P(GyroDispatch, DdsReplayEquivalence, ::testing::Values("listener", "waitset"),
                         [](const auto& param_info) { return std::string(param_info.param); });

TEST(DdsServices, SimulatorKilledGoesLostAndRecovers_ServiceKilledResumes) {
  const dds_domainid_t domain = 163;
  ServiceFiles files(100.0, 1.0);
  Observer observer(domain);
  auto fusion = std::make_unique<TetraProcess>(
      std::vector<std::string>{"fusion", "--config", files.config, "--domain", d(domain)},
      files.dir.file("fusion.log"));
  const std::vector<std::string> sim_cmd = {"sim",      "static",  "--dds",     "--dds-unit", "tetra-1",
                                            "--domain", d(domain), "--rate-hz", "100",        "--minutes",
                                            "10",       "--speed", "1"};
  auto sim = std::make_unique<TetraProcess>(sim_cmd, files.dir.file("sim1.log"));
  const auto health = [&]() -> const dds::HealthView* {
    const auto it = observer.health.find("tetra-1");
    return it == observer.health.end() ? nullptr : &it->second;
  };
  ASSERT_TRUE(observer.wait_until([&] {
    const auto* h = health();
    return h && h->health.mode == fdi::Mode::kNominal && h->health.counters.epochs_accepted > 50;
  })) << read_file(files.dir.file("fusion.log"));

  const std::int64_t killed_sim_ns = now_ns();
  sim->kill_now(SIGKILL);
  // The deadline (3 periods) marks every gyro absent long before the writer's lease (1 s) ends.
  ASSERT_TRUE(observer.wait_until([&] {
    const auto* h = health();
    if (!h || h->health.mode != fdi::Mode::kLost) return false;
    for (const auto& g : h->health.gyros) {
      if (g.state != fdi::GyroState::kAbsent) return false;
    }
    return true;
  })) << read_file(files.dir.file("fusion.log"));
  EXPECT_GE(health()->counters.deadlines_missed, 4U);
  // A figure for the record, not a pass criterion (timing depends on the machine's load).
  std::printf("[ figure ] simulator kill -9 to Health LOST with all gyros absent: %.1f ms (deadline 30 ms)\n",
              static_cast<double>(now_ns() - killed_sim_ns) * 1e-6);

  sim = std::make_unique<TetraProcess>(sim_cmd, files.dir.file("sim2.log"));
  ASSERT_TRUE(observer.wait_until([&] {
    const auto* h = health();
    return h && h->health.mode == fdi::Mode::kNominal && h->counters.sensor_restarts == 1;
  })) << read_file(files.dir.file("fusion.log"));

  fusion->kill_now(SIGKILL);
  observer.drain();
  observer.attitudes.clear();
  const std::int64_t restart_ns = now_ns();
  fusion = std::make_unique<TetraProcess>(
      std::vector<std::string>{"fusion", "--config", files.config, "--domain", d(domain)},
      files.dir.file("fusion2.log"));
  ASSERT_TRUE(observer.wait_until([&] { return !observer.attitudes.empty(); }))
      << read_file(files.dir.file("fusion2.log"));
  std::printf("[ figure ] service kill -9, new service started: first Attitude after %.1f ms\n",
              static_cast<double>(now_ns() - restart_ns) * 1e-6);
  ASSERT_TRUE(observer.wait_until([&] { return observer.attitudes.size() >= 10; }));
}

TEST(DdsServices, MalformedTrafficIsCountedNeverMixedNeverACrash) {
  const dds_domainid_t domain = 164;
  ServiceFiles files(100.0, 1.0);
  Observer observer(domain);
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", d(domain)},
                      files.dir.file("fusion.log"));
  auto writer = dds::Writer<tetra_GyroSample>::create(observer.participant(), observer.topics().gyro_sample,
                                                      dds::gyro_sample_qos(std::chrono::milliseconds(10)));
  ASSERT_TRUE(writer.ok());
  // Wait for the service's reader (a DDS condition: the publication-matched status).
  ASSERT_TRUE(observer.wait_until([&] { return *writer->matched_readers() >= 1; }));

  const Calibration cal = seed_as_built_unit();
  std::uint64_t seq = 0;
  std::int64_t stamp = 0;
  const auto sample = [&](const std::string& unit, int gyro, std::uint64_t s, std::int64_t t, double raw) {
    tetra_GyroSample m{};
    EXPECT_TRUE(dds::copy_bounded(m.unit, unit, "unit").ok());
    m.gyro = static_cast<std::uint16_t>(gyro);
    m.seq = s;
    m.stamp_ns = t;
    m.raw = raw;
    EXPECT_TRUE(writer->write(m).ok());
  };
  const auto epoch = [&](double nan_on_gyro = 0) {
    ++seq;
    stamp += 10'000'000;
    for (int g = 1; g <= 4; ++g)
      sample("tetra-1", g, seq, stamp,
             g == nan_on_gyro ? std::nan("") : cal.gyros[static_cast<std::size_t>(g - 1)].bias_V);
  };
  for (int k = 0; k < 20; ++k) epoch();
  epoch(3);                                                           // one NaN sample (gyro 3)
  sample("tetra-1", 1, seq, stamp + 10'000'000, 0.0);                 // duplicate sequence number
  sample("tetra-1", 2, seq - 5, stamp + 10'000'000, 0.0);             // sequence number going backwards
  sample("tetra-1", 7, 1, stamp + 10'000'000, 0.0);                   // no gyro 7 on this unit
  for (int g = 1; g <= 4; ++g) sample("intruder", g, 1, stamp, 5.0);  // another unit's samples
  for (int k = 0; k < 20; ++k) epoch();
  sample("tetra-1", 4, seq + 1, stamp - 20'000'000, 0.0);  // stamp going backwards
  ++seq;  // gyro 4 used that number: the others skip it (a gap of one each for gyros 1..3)
  for (int k = 0; k < 20; ++k) epoch();

  ASSERT_TRUE(observer.wait_until([&] {
    const auto it = observer.health.find("tetra-1");
    return it != observer.health.end() && it->second.health.counters.epochs_accepted >= 61;
  })) << read_file(files.dir.file("fusion.log"));
  const auto& h = observer.health.at("tetra-1");
  EXPECT_EQ(h.health.counters.samples_invalid, 1U);
  EXPECT_EQ(h.counters.samples_duplicate, 1U);
  EXPECT_EQ(h.counters.samples_out_of_order, 2U);  // the backward sequence number and the backward stamp
  EXPECT_EQ(h.counters.samples_unknown_gyro, 1U);
  EXPECT_EQ(h.counters.samples_gap, 3U);
  EXPECT_EQ(h.counters.samples_other_unit, 4U);
  EXPECT_EQ(observer.health.count("intruder"), 0U);  // nobody fuses the intruder's samples
  EXPECT_EQ(observer.attitude_units.count("intruder"), 0U);
  EXPECT_EQ(fusion.signal_and_wait(SIGINT), 0) << "the service survived and shut down cleanly";
}

TEST(DdsServices, GlitchingStampsAndSequenceNumbersFromAnotherProcessNeverBlindTheService) {
  // A simulator feeds good samples; this process, a second writer on the same instances, publishes one
  // of each glitch (docs/dds.md, "Epoch assembly"). 50 Hz: a 60 ms deadline, so a loaded machine's
  // scheduling does not make gyros absent.
  const dds_domainid_t domain = 197;
  ServiceFiles files(50.0, 1.0);
  Observer observer(domain);
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", d(domain)},
                      files.dir.file("fusion.log"));
  TetraProcess sim({"sim", "static", "--dds", "--dds-unit", "tetra-1", "--domain", d(domain), "--rate-hz",
                    "50", "--minutes", "1", "--speed", "1"},
                   files.dir.file("sim.log"));
  const auto health = [&]() -> const dds::HealthView* {
    const auto it = observer.health.find("tetra-1");
    return it == observer.health.end() ? nullptr : &it->second;
  };
  ASSERT_TRUE(observer.wait_until([&] {
    const auto* h = health();
    return h && h->health.mode == fdi::Mode::kNominal && h->health.counters.epochs_accepted > 25;
  })) << read_file(files.dir.file("fusion.log"));
  auto writer = dds::Writer<tetra_GyroSample>::create(observer.participant(), observer.topics().gyro_sample,
                                                      dds::gyro_sample_qos(std::chrono::milliseconds(20)));
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(observer.wait_until([&] { return *writer->matched_readers() >= 1; }));

  const Calibration cal = seed_as_built_unit();
  const auto glitch = [&](int gyro, std::uint64_t seq, std::int64_t stamp_ns) {
    tetra_GyroSample m{};
    EXPECT_TRUE(dds::copy_bounded(m.unit, "tetra-1", "unit").ok());
    m.gyro = static_cast<std::uint16_t>(gyro);
    m.seq = seq;
    m.stamp_ns = stamp_ns;
    m.raw = cal.gyros[static_cast<std::size_t>(gyro - 1)].bias_V;
    EXPECT_TRUE(writer->write(m).ok());
  };
  observer.drain();
  ASSERT_FALSE(observer.attitudes.empty());
  const std::int64_t now_stamp = observer.attitudes.back().stamp_ns;  // the unit's time, about now
  const std::uint64_t accepted_before = health()->health.counters.epochs_accepted;
  const std::uint64_t deadlines_before = health()->counters.deadlines_missed;
  constexpr std::int64_t kMillionSeconds = 1'000'000'000'000'000;
  glitch(2, 1, std::numeric_limits<std::int64_t>::max());
  glitch(3, 1, std::numeric_limits<std::int64_t>::min());
  for (int g = 1; g <= 4; ++g) glitch(g, 1, now_stamp + kMillionSeconds);  // one epoch 1e6 s ahead
  glitch(1, 1, now_stamp - kMillionSeconds);
  glitch(4, std::numeric_limits<std::uint64_t>::max(), now_stamp + 20'000'000);  // plausible time
  glitch(1, 1'000'000'000'000, now_stamp + 20'000'000);
  observer.attitudes.clear();
  // Health LOST not explained by a stall of the whole stream (a missed deadline: a loaded machine) would
  // be the glitches blinding the unit.
  int lost_unexplained = 0;
  int lost_in_stall = 0;
  // 7 time outliers; the two sequence numbers are discontinuities, or time outliers when this process
  // was descheduled long enough for its "now" to fall out of the window: 9 in all, exactly.
  ASSERT_TRUE(observer.wait_until([&] {
    const auto* h = health();
    if (h && h->health.mode == fdi::Mode::kLost) {
      ++(h->counters.deadlines_missed > deadlines_before ? lost_in_stall : lost_unexplained);
    }
    return h && h->health.counters.epochs_accepted >= accepted_before + 100 &&
           h->counters.time_outlier + h->counters.seq_discontinuity == 9 &&
           h->health.mode == fdi::Mode::kNominal && h->health.used == 0xFU;
  })) << read_file(files.dir.file("fusion.log"));
  const auto& h = *health();
  std::printf(
      "[ figure ] glitches: time_outlier %llu, seq_discontinuity %llu; then %zu attitudes, Health LOST "
      "seen %d times in stalls (deadlines missed %llu)\n",
      static_cast<unsigned long long>(h.counters.time_outlier),
      static_cast<unsigned long long>(h.counters.seq_discontinuity), observer.attitudes.size(), lost_in_stall,
      static_cast<unsigned long long>(h.counters.deadlines_missed - deadlines_before));
  EXPECT_GE(h.counters.time_outlier, 7U);
  EXPECT_EQ(h.counters.sensor_restarts, 0U);
  EXPECT_LT(h.counters.samples_gap, 1000U) << "no counter set to garbage by one sample";
  EXPECT_EQ(h.health.mode, fdi::Mode::kNominal);
  EXPECT_EQ(h.health.used, 0xFU);
  EXPECT_GE(observer.attitudes.size(), 90U) << "attitude keeps flowing";
  EXPECT_FALSE(observer.has_event(fdi::EventType::kIsolated));
  EXPECT_EQ(lost_unexplained, 0) << read_file(files.dir.file("fusion.log"));
  EXPECT_EQ(fusion.signal_and_wait(SIGINT), 0);
}

TEST(DdsServices, DefaultLivelinessWriterMatchesAndAnotherUnitIsWarnedAbout) {
  // A sensor driver with the topic table's reliability, durability, history and deadline but the
  // default liveliness matches the service; samples for another unit only are warned about, by name.
  const dds_domainid_t domain = 165;
  ServiceFiles files(100.0, 1.0);
  Observer observer(domain);
  TetraProcess fusion({"fusion", "--config", files.config, "--domain", d(domain)},
                      files.dir.file("fusion.log"));
  dds::Qos qos;
  qos.reliable()
      .volatile_durability()
      .keep_last(dds::kGyroSampleDepth)
      .deadline(std::chrono::milliseconds(30));
  auto writer =
      dds::Writer<tetra_GyroSample>::create(observer.participant(), observer.topics().gyro_sample, qos);
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(observer.wait_until([&] { return *writer->matched_readers() >= 1; }))
      << read_file(files.dir.file("fusion.log"));
  for (std::uint64_t k = 1; k <= 20; ++k) {
    tetra_GyroSample m{};
    EXPECT_TRUE(dds::copy_bounded(m.unit, "tetra-9", "unit").ok());
    m.gyro = 1;
    m.seq = k;
    m.stamp_ns = static_cast<std::int64_t>(k) * 10'000'000;
    EXPECT_TRUE(writer->write(m).ok());
  }
  ASSERT_TRUE(observer.wait_until([&] {
    return read_file(files.dir.file("fusion.log")).find("hearing GyroSample for unit 'tetra-9'") !=
           std::string::npos;
  })) << read_file(files.dir.file("fusion.log"));
  EXPECT_EQ(read_file(files.dir.file("fusion.log")).find("incompatible QoS"), std::string::npos);
  EXPECT_EQ(fusion.signal_and_wait(SIGINT), 0);
}

TEST(DdsServices, RealtimeOptionLocksMemoryAndSchedulesTheStepThreadsOrWarnsAndRunsOn) {
  // --realtime 10: mlockall and SCHED_FIFO for the waitset thread and the listener's (receive) thread,
  // each applied or, without the privilege, warned about by name; either way the service fuses epochs.
  for (const char* dispatch : {"listener", "waitset"}) {
    const dds_domainid_t domain = std::string(dispatch) == "listener" ? 198 : 199;
    ServiceFiles files(50.0, 1.0, "tetra-1", dispatch);
    Observer observer(domain);
    TetraProcess fusion({"fusion", "--config", files.config, "--domain", d(domain), "--realtime", "10"},
                        files.dir.file("fusion.log"));
    TetraProcess sim({"sim", "static", "--dds", "--dds-unit", "tetra-1", "--domain", d(domain), "--rate-hz",
                      "50", "--minutes", "1", "--speed", "1"},
                     files.dir.file("sim.log"));
    ASSERT_TRUE(observer.wait_until([&] {
      const auto it = observer.health.find("tetra-1");
      return it != observer.health.end() && it->second.health.counters.epochs_accepted > 25;
    })) << dispatch
        << "\n"
        << read_file(files.dir.file("fusion.log"));
    EXPECT_EQ(fusion.signal_and_wait(SIGINT), 0);
    const std::string log = read_file(files.dir.file("fusion.log"));
    EXPECT_NE(log.find("realtime: memory locked, SCHED_FIFO priority 10"), std::string::npos) << log;
    const bool locked = log.find("--realtime: memory locked (mlockall") != std::string::npos;
    const bool lock_warned =
        log.find("--realtime: mlockall(MCL_CURRENT | MCL_FUTURE) failed: ") != std::string::npos;
    EXPECT_NE(locked, lock_warned) << log;
    std::vector<std::string> threads = {"waitset thread"};
    if (std::string(dispatch) == "listener") threads.emplace_back("receive thread (gyro listener)");
    for (const auto& thread : threads) {
      const bool fifo =
          log.find("--realtime: " + thread + " under SCHED_FIFO at priority 10") != std::string::npos;
      const bool warned = log.find("--realtime: " + thread +
                                   ": pthread_setschedparam(SCHED_FIFO, 10) failed: ") != std::string::npos;
      EXPECT_NE(fifo, warned) << thread << "\n" << log;
    }
    std::printf("[ figure ] --realtime with gyro_dispatch %s: memory %s\n", dispatch,
                locked ? "locked" : "not locked (warned)");
  }
  // The priority is checked when the options are parsed.
  for (const char* bad : {"0", "100", "high"}) {
    const auto r = run_tetra(std::string("fusion --config /nonexistent/fusion.yaml --realtime ") + bad);
    EXPECT_EQ(r.exit_status, 2) << bad;
    EXPECT_NE(r.err.find("--realtime"), std::string::npos) << r.err;
  }
}

TEST(DdsServices, CommandLineErrorsAndAbsentServicesGiveTheExitStatusOfTheContract) {
  // Bad usage or input: 2 and one line naming what is wrong.
  auto r = run_tetra("fusion --config /nonexistent/fusion.yaml");
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("/nonexistent/fusion.yaml"), std::string::npos) << r.err;
  TempDir dir;
  write_file(dir.file("f.yaml"), "calibration: cal.yaml\nsampel_rate_hz: 100\n");
  r = run_tetra("fusion --config " + dir.file("f.yaml"));
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("f.yaml:2:"), std::string::npos) << r.err;
  EXPECT_EQ(run_tetra("command --unit tetra-1 exclude").exit_status, 2);    // which gyro?
  EXPECT_EQ(run_tetra("command --unit tetra-1 reset 2").exit_status, 2);    // reset takes none
  EXPECT_EQ(run_tetra("command --unit tetra-1 explode 2").exit_status, 2);  // no such command
  EXPECT_EQ(run_tetra("record --unit tetra-1").exit_status, 2);             // -o is required
  EXPECT_EQ(run_tetra("monitor --period 2").exit_status, 2);                // < 2 Hz refused
  for (const char* sub : {"fusion", "monitor", "command", "record", "demo"}) {
    EXPECT_EQ(run_tetra(std::string(sub) + " --help").exit_status, 0) << sub;
  }
  // Nobody on the domain: 1, and the reason.
  r = run_tetra("command --unit tetra-1 reset --timeout 0.3 --domain 165");
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("no fusion service found"), std::string::npos) << r.err;
  r = run_tetra("monitor --once --timeout 0.3 --domain 165");
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("no health"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace tetra::test
