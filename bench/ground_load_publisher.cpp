// Load for the ground station (bench/ground_load.py): plays the fusion services of many units at
// once — Attitude at --rate Hz and Health every 0.5 s per unit, an FdiEvent every 10 s — for
// --seconds, on --domain. Prints what it wrote.
//
//   ground_load_publisher --domain D [--units 10] [--rate 100] [--seconds 600]

#include <time.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_clock.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"

namespace {

using tetra::bench::now_ns;
using tetra::bench::sleep_until_ns;

template <class T>
T must(tetra::Result<T> r, const char* what) {
  if (!r) {
    std::fprintf(stderr, "ground_load_publisher: %s: %s\n", what, r.error().message.c_str());
    std::exit(1);
  }
  return std::move(r).value();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tetra;
  int domain = 0;
  int units = 10;
  double rate_hz = 100.0;
  double seconds = 600.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const double value = std::atof(argv[i + 1]);
    if (key == "--domain") domain = static_cast<int>(value);
    if (key == "--units") units = static_cast<int>(value);
    if (key == "--rate") rate_hz = value;
    if (key == "--seconds") seconds = value;
  }
  auto participant = must(dds::Participant::create(static_cast<dds_domainid_t>(domain)), "participant");
  auto topics = must(dds::Topics::create(participant), "topics");
  auto attitude_writer =
      must(dds::Writer<tetra_Attitude>::create(participant, topics.attitude, dds::attitude_qos()),
           "attitude writer");
  auto health_writer =
      must(dds::Writer<tetra_Health>::create(participant, topics.health, dds::health_qos()), "health writer");
  auto event_writer =
      must(dds::Writer<tetra_FdiEvent2>::create(participant, topics.event, dds::event_qos()), "event writer");

  std::vector<std::string> names;
  for (int u = 0; u < units; ++u) names.push_back("load-" + std::to_string(u + 1));
  fdi::Health health;
  health.gyros.resize(4);
  health.used = 0b1111;
  health.chi2_threshold = 37.3;
  health.cusum_threshold = 41.1;
  const service::AssemblerCounters counters{};
  const std::int64_t period_ns = seconds_to_ns(1.0 / rate_hz);
  const std::int64_t epochs = static_cast<std::int64_t>(seconds * rate_hz);
  const std::int64_t health_every = std::max<std::int64_t>(1, static_cast<std::int64_t>(0.5 * rate_hz));
  const std::int64_t event_every = static_cast<std::int64_t>(10.0 * rate_hz);
  std::uint64_t attitudes = 0;
  std::uint64_t healths = 0;
  std::uint64_t events = 0;
  const std::int64_t start = now_ns() + 500'000'000;  // discovery first
  for (std::int64_t k = 0; k < epochs; ++k) {
    sleep_until_ns(start + k * period_ns);
    fdi::AttitudeEstimate a;
    a.stamp_ns = k * period_ns;
    a.q_RB =
        Quaternion(Eigen::AngleAxisd(1e-3 * static_cast<double>(k) * kDegToRad, Eigen::Vector3d::UnitY()));
    a.gyros = 0b1111;
    for (std::size_t u = 0; u < names.size(); ++u) {
      tetra_Attitude wire{};
      if (dds::to_wire(names[u], a, wire) && attitude_writer.write(wire)) ++attitudes;
      if (k % health_every == 0) {
        health.stamp_ns = a.stamp_ns;
        health.chi2 = 1.0 + 0.1 * static_cast<double>(k % 7);
        dds::WireHealth h;
        if (dds::to_wire(names[u], health, counters, h)) {
          h.msg.health_period_s = 0.5;
          if (health_writer.write(h.msg)) ++healths;
        }
      }
      if (k % event_every == event_every - 1) {
        dds::EventView view{
            names[u], static_cast<std::uint64_t>(k / event_every + 1), 0, fdi::FdiEvent{}, {}};
        view.event.stamp_ns = a.stamp_ns;
        view.event.type = fdi::EventType::kDetected;
        view.event.test = fdi::DetectionTest::kChi2;
        dds::WireEvent event_wire;
        if (dds::to_wire(view, event_wire) && event_writer.write(event_wire.msg)) ++events;
      }
    }
  }
  std::printf(
      "ground_load_publisher: %d units, %.0f s at %.0f Hz: %llu attitudes, %llu health, %llu events "
      "written\n",
      units, seconds, rate_hz, static_cast<unsigned long long>(attitudes),
      static_cast<unsigned long long>(healths), static_cast<unsigned long long>(events));
  return 0;
}
