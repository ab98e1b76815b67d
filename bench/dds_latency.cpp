// Latency of the fusion service on DDS: from the write of an epoch's last GyroSample to the receive
// of that epoch's Attitude, measured by one process that plays the sensor and the consumer, against
// a running `tetra fusion` (bench/dds_latency.sh starts everything and runs ddsperf beside it).
//
//   dds_latency --domain D [--epochs N] [--rate HZ] [--unit U] [--receive waitset|listener]
//               [--gyro-spacing-us US]
// --receive: how this program learns of an Attitude: a waitset wakes its main thread (like
//   `ddsperf ... waitset`), or a listener on Cyclone's receive thread stamps it (like ddsperf's default).
// --gyro-spacing-us: time between the writes of one epoch's four samples (0: back to back, one burst).
//   dds_latency --write-calibration CAL.yaml      (the calibration the service must use)
// Prints p50, p90, p99 and max in microseconds, and the number of epochs without an Attitude.

#include <time.h>

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

#include "bench_clock.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"

namespace {

using tetra::bench::now_ns;
using tetra::bench::sleep_until_ns;

//! What the Attitude listener saw last, for the main thread (listener mode).
struct Arrivals {
  std::mutex mutex;
  std::condition_variable changed;
  std::int64_t stamp_ns = -1;   //!< [ns] sensor time of the last Attitude taken
  std::int64_t arrived_ns = 0;  //!< [ns] local monotonic time it was taken
};

void on_attitude(dds_entity_t reader, void* arg) {
  auto& arrivals = *static_cast<Arrivals*>(arg);
  void* samples[8] = {nullptr};
  dds_sample_info_t infos[8];
  const dds_return_t n = dds_take(reader, samples, infos, 8, 8);
  const std::int64_t now = now_ns();
  std::int64_t stamp = -1;
  for (dds_return_t i = 0; i < n; ++i) {
    if (infos[i].valid_data)
      stamp = std::max(stamp, static_cast<const tetra_Attitude*>(samples[i])->stamp_ns);
  }
  if (n > 0) (void)dds_return_loan(reader, samples, n);
  if (stamp < 0) return;
  {
    std::lock_guard lock(arrivals.mutex);
    arrivals.stamp_ns = stamp;
    arrivals.arrived_ns = now;
  }
  arrivals.changed.notify_one();
}

int fail(const std::string& what) {
  std::fprintf(stderr, "dds_latency: %s\n", what.c_str());
  return 1;
}

}  // namespace

namespace {

int run(int argc, char** argv) {
  using namespace tetra;
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  int epochs = 3000;
  double rate_hz = 100.0;
  std::string unit = "tetra-1";
  bool listener = false;
  std::int64_t spacing_ns = 0;
  if (argc == 3 && !std::strcmp(argv[1], "--write-calibration")) {
    // The calibration the service needs for what this program writes (the seed's as-built unit).
    Calibration cal = seed_as_built_unit();
    cal.unit = unit;
    auto status = write_calibration(argv[2], cal);
    return status ? 0 : fail(status.error().message);
  }
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--domain"))
      domain = static_cast<dds_domainid_t>(std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--epochs"))
      epochs = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--rate"))
      rate_hz = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--unit"))
      unit = argv[i + 1];
    else if (!std::strcmp(argv[i], "--receive") && !std::strcmp(argv[i + 1], "listener"))
      listener = true;
    else if (!std::strcmp(argv[i], "--receive") && !std::strcmp(argv[i + 1], "waitset"))
      listener = false;
    else if (!std::strcmp(argv[i], "--gyro-spacing-us"))
      spacing_ns = static_cast<std::int64_t>(std::atof(argv[i + 1]) * 1e3);
    else
      return fail(std::string("unknown option ") + argv[i]);
  }
  const std::int64_t period_ns = seconds_to_ns(1.0 / rate_hz);
  auto participant = dds::Participant::create(domain);
  if (!participant) return fail(participant.error().message);
  auto topics = dds::Topics::create(*participant);
  if (!topics) return fail(topics.error().message);
  auto writer = dds::Writer<tetra_GyroSample>::create(
      *participant, topics->gyro_sample, dds::gyro_sample_qos(std::chrono::nanoseconds(period_ns)));
  if (!writer) return fail(writer.error().message);
  auto reader = dds::Reader<tetra_Attitude>::create(*participant, topics->attitude, dds::attitude_qos());
  if (!reader) return fail(reader.error().message);
  auto waitset = dds::WaitSet::create(*participant);
  auto data = dds::Condition::data_available(reader->handle());
  if (!waitset || !data || !waitset->attach(data->handle(), 1)) return fail("waitset");
  if (dds_set_status_mask(writer->handle(), DDS_PUBLICATION_MATCHED_STATUS) < 0 ||
      dds_set_status_mask(reader->handle(), DDS_SUBSCRIPTION_MATCHED_STATUS) < 0 ||
      !waitset->attach(writer->handle(), 2) || !waitset->attach(reader->handle(), 3)) {
    return fail("status conditions");
  }
  std::vector<std::intptr_t> triggered;
  const std::int64_t give_up = now_ns() + 10'000'000'000;
  while (*writer->matched_readers() == 0 || *reader->matched_writers() == 0) {
    if (now_ns() > give_up) return fail("no fusion service on the domain");
    (void)waitset->wait(std::chrono::milliseconds(100), triggered);
    std::uint32_t status = 0;
    (void)dds_take_status(writer->handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
    (void)dds_take_status(reader->handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
  }

  Arrivals arrivals;
  if (listener) {
    dds_listener_t* l = dds_create_listener(&arrivals);
    dds_lset_data_available(l, on_attitude);
    const dds_return_t rc = dds_set_listener(reader->handle(), l);
    dds_delete_listener(l);
    if (rc < 0) return fail("set listener");
  }

  // Raw values at the biases: zero rate on every gyro, a quiet NOMINAL unit.
  const Calibration cal = seed_as_built_unit();
  tetra_GyroSample sample{};
  (void)dds::copy_bounded(sample.unit, unit, "unit");
  std::vector<double> latency_us;
  int missing = 0;
  const int warmup = 100;
  std::int64_t next = now_ns();
  for (int k = 0; k < warmup + epochs; ++k) {
    const std::int64_t stamp = static_cast<std::int64_t>(k + 1) * period_ns;
    std::int64_t t0 = 0;
    for (int g = 1; g <= 4; ++g) {
      sample.gyro = static_cast<std::uint16_t>(g);
      sample.seq = static_cast<std::uint64_t>(k) + 1;
      sample.stamp_ns = stamp;
      sample.raw = cal.gyros[static_cast<std::size_t>(g - 1)].bias_V;
      if (g > 1 && spacing_ns > 0) sleep_until_ns(now_ns() + spacing_ns);
      if (g == 4) t0 = now_ns();
      if (!writer->write(sample)) return fail("write");
    }
    bool received = false;
    std::int64_t t1 = 0;
    const std::int64_t deadline = t0 + 500'000'000;
    if (listener) {
      std::unique_lock lock(arrivals.mutex);
      received = arrivals.changed.wait_for(lock, std::chrono::nanoseconds(deadline - t0),
                                           [&] { return arrivals.stamp_ns >= stamp; });
      t1 = arrivals.arrived_ns;
    } else {
      while (!received) {
        auto taken = reader->take([&](const tetra_Attitude& a, const dds_sample_info_t&) {
          if (a.stamp_ns == stamp) received = true;
        });
        if (!taken) return fail("take");
        if (received) break;
        const std::int64_t now = now_ns();
        if (now >= deadline) break;
        (void)waitset->wait(std::chrono::nanoseconds(deadline - now), triggered);
      }
      t1 = now_ns();
    }
    if (k < warmup) {
      // Warm-up: the service's writer may match this reader after its first Attitude (volatile).
    } else if (!received) {
      ++missing;
    } else {
      latency_us.push_back(static_cast<double>(t1 - t0) * 1e-3);
    }
    next += period_ns;
    sleep_until_ns(std::max(next, now_ns()));
    if (!listener) (void)reader->take([](const tetra_Attitude&, const dds_sample_info_t&) {});
  }
  if (latency_us.empty()) return fail("no Attitude received");
  std::sort(latency_us.begin(), latency_us.end());
  const auto pct = [&](double p) {
    return latency_us[std::min(latency_us.size() - 1,
                               static_cast<std::size_t>(p * static_cast<double>(latency_us.size())))];
  };
  std::printf(
      "gyro-write-to-attitude latency (%s) over %zu epochs at %.0f Hz: p50 %.1f us  p90 %.1f us  p99 %.1f us "
      " max "
      "%.1f us  "
      "(no attitude: %d)\n",
      listener ? "listener" : "waitset", latency_us.size(), rate_hz, pct(0.5), pct(0.9), pct(0.99),
      latency_us.back(), missing);
  return missing == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    return fail(std::string("internal error: ") + e.what());
  }
}
