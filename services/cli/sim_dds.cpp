#include "sim_dds.hpp"

#include <deque>
#include <iostream>

#include "cli_common.hpp"
#include "dds_common.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"

namespace tetra::cli {

namespace {
enum Token : std::intptr_t { kAttitude = 1, kMatched, kShutdown };
constexpr std::int64_t kDiscoverySettle_ns = 200'000'000;  //!< [ns] see run_sim_dds
}  // namespace

void add_sim_dds_options(CLI::App& app, SimDdsOptions& options) {
  app.add_flag("--dds", options.enabled,
               "publish on DDS (GyroSample, AttitudeReference) instead of writing files, "
               "and score the Attitude received against the truth");
  app.add_option("--speed", options.speed,
                 "--dds: 1 = real time, X = X times faster, 0 = as fast as possible")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--dds-unit", options.unit, "--dds: the unit's key on the wire (default: the unit's name)");
  app.add_option("--wait-readers", options.wait_readers, "--dds: gyro readers to wait for before publishing")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wait-timeout", options.wait_timeout_s, "[s] --dds: how long to wait for them")
      ->check(CLI::PositiveNumber);
  add_domain_option(app, options.domain);
}

Result<SimDdsScore> run_sim_dds(sim::Simulator& simulator, const SimDdsOptions& options,
                                const dds::ShutdownSignal* shutdown,
                                const std::function<void(const SimDdsScore&)>& on_progress) {
  const std::string unit = options.unit.empty() ? simulator.scenario().unit.unit : options.unit;
  const int n = simulator.gyro_count();
  const double rate_hz = simulator.scenario().rate_hz;
  auto participant = dds::Participant::create(options.domain, unit);
  if (!participant) return participant.error();
  auto topics = dds::Topics::create(*participant);
  if (!topics) return topics.error();
  // The deadline offered is 3 periods of the wall-clock rate (none when unpaced).
  const auto period =
      options.speed > 0 ? std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / (rate_hz * options.speed)))
                        : std::chrono::nanoseconds(0);
  dds::Qos gyro_qos = dds::gyro_sample_qos(period);
  gyro_qos.no_autodispose();
  auto gyro_writer = dds::Writer<tetra_GyroSample>::create(*participant, topics->gyro_sample, gyro_qos);
  if (!gyro_writer) return gyro_writer.error();
  auto reference_writer =
      dds::Writer<tetra_AttitudeReference>::create(*participant, topics->reference, dds::reference_qos());
  if (!reference_writer) return reference_writer.error();
  dds::Qos attitude_qos;
  attitude_qos.reliable().volatile_durability().keep_last(1024);  // score every epoch, not only the latest
  auto attitude_reader = dds::Reader<tetra_Attitude>::create(*participant, topics->attitude, attitude_qos);
  if (!attitude_reader) return attitude_reader.error();
  auto waitset = dds::WaitSet::create(*participant);
  if (!waitset) return waitset.error();
  auto data = dds::Condition::data_available(attitude_reader->handle());
  if (!data) return data.error();
  if (auto s = waitset->attach(data->handle(), kAttitude); !s) return s.error();
  if (dds_set_status_mask(gyro_writer->handle(), DDS_PUBLICATION_MATCHED_STATUS) < 0) {
    return failure("DDS: cannot enable the publication-matched status");
  }
  if (auto s = waitset->attach(gyro_writer->handle(), kMatched); !s) return s.error();
  auto guard = dds::Condition::guard(*participant);
  if (!guard) return guard.error();
  if (auto s = waitset->attach(guard->handle(), kShutdown); !s) return s.error();
  if (shutdown != nullptr) const_cast<dds::ShutdownSignal*>(shutdown)->set_guard(guard->handle());
  const auto stop_requested = [&] { return shutdown != nullptr && shutdown->requested(); };

  std::vector<std::intptr_t> triggered;
  // Wait for the readers (the service, a recorder) so that the first samples are not lost.
  const std::int64_t give_up = monotonic_ns() + static_cast<std::int64_t>(options.wait_timeout_s * 1e9);
  for (;;) {
    std::uint32_t status = 0;
    (void)dds_take_status(gyro_writer->handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
    auto matched = gyro_writer->matched_readers();
    if (!matched) return matched.error();
    if (static_cast<int>(*matched) >= options.wait_readers) break;
    if (stop_requested()) return failure("interrupted while waiting for readers");
    const std::int64_t now = monotonic_ns();
    if (now >= give_up) {
      return failure("only " + std::to_string(*matched) + " of " + std::to_string(options.wait_readers) +
                     " GyroSample readers appeared within " + fixed(options.wait_timeout_s, 1) + " s");
    }
    if (auto s = waitset->wait(std::chrono::nanoseconds(give_up - now), triggered); !s) return s.error();
  }

  // A volatile reader receives only what is written after IT has discovered the writer, which can
  // be a moment after the writer has discovered the reader. So wait, when a service for this unit
  // exists (its Health arrives within a second), until its Health says it hears a GyroSample writer.
  if (options.wait_readers > 0) {
    auto health_reader = dds::Reader<tetra_Health>::create(*participant, topics->health, dds::health_qos());
    if (!health_reader) return health_reader.error();
    auto health_data = dds::Condition::data_available(health_reader->handle());
    if (!health_data) return health_data.error();
    auto health_waitset = dds::WaitSet::create(*participant);
    if (!health_waitset) return health_waitset.error();
    if (auto s = health_waitset->attach(health_data->handle(), 1); !s) return s.error();
    bool service_seen = false;
    bool service_hears = false;
    const std::int64_t first_give_up = monotonic_ns() + 1'000'000'000;
    const std::int64_t hears_give_up =
        monotonic_ns() + static_cast<std::int64_t>(options.wait_timeout_s * 1e9);
    std::vector<std::intptr_t> fired;
    for (;;) {
      auto taken = health_reader->take([&](const tetra_Health& h, const dds_sample_info_t&) {
        if (dds::from_wire(h.unit) != unit) return;
        service_seen = true;
        service_hears = service_hears || h.gyro_writers > 0;
      });
      if (!taken) return taken.error();
      const std::int64_t now = monotonic_ns();
      const std::int64_t limit = service_seen ? hears_give_up : first_give_up;
      if (service_hears || now >= limit || stop_requested()) break;
      if (auto s = health_waitset->wait(std::chrono::nanoseconds(limit - now), fired); !s) return s.error();
    }
  }

  // And (briefly) for the service's Attitude writer, so that the first epochs are scored too.
  if (options.wait_readers > 0) {
    if (dds_set_status_mask(attitude_reader->handle(), DDS_SUBSCRIPTION_MATCHED_STATUS) < 0) {
      return failure("DDS: cannot enable the subscription-matched status");
    }
    if (auto s = waitset->attach(attitude_reader->handle(), kMatched); !s) return s.error();
    const std::int64_t attitude_give_up = monotonic_ns() + 1'000'000'000;
    for (;;) {
      std::uint32_t status = 0;
      (void)dds_take_status(attitude_reader->handle(), &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
      auto matched = attitude_reader->matched_writers();
      if (!matched) return matched.error();
      const std::int64_t now = monotonic_ns();
      if (*matched > 0 || now >= attitude_give_up || stop_requested()) break;
      if (auto s = waitset->wait(std::chrono::nanoseconds(attitude_give_up - now), triggered); !s)
        return s.error();
    }
  }

  // Other readers (a recorder) give no such sign of having discovered our writer: allow them a
  // settling time well above the 3–20 ms discovery takes on loopback, before the first sample.
  if (options.wait_readers > 1) {
    const std::int64_t settle_until = monotonic_ns() + kDiscoverySettle_ns;
    for (std::int64_t now = monotonic_ns(); now < settle_until && !stop_requested(); now = monotonic_ns()) {
      if (auto s = waitset->wait(std::chrono::nanoseconds(settle_until - now), triggered); !s)
        return s.error();
    }
  }

  SimDdsScore score;
  std::deque<std::pair<std::int64_t, Quaternion>> truth;  // (stamp, q_RB) of epochs not yet scored
  std::int64_t last_stamp = 0;
  const auto take_attitudes = [&]() -> Status {
    auto taken = attitude_reader->take([&](const tetra_Attitude& msg, const dds_sample_info_t&) {
      if (dds::from_wire(msg.unit) != unit) return;
      while (!truth.empty() && truth.front().first < msg.stamp_ns) {
        if (score.missing == 0) score.first_missing_s = ns_to_seconds(truth.front().first);
        ++score.missing;  // an epoch published, but no attitude for it
        truth.pop_front();
      }
      if (truth.empty() || truth.front().first != msg.stamp_ns) return;
      const auto estimate = dds::from_wire(msg);
      const double error_deg = angle_between(estimate.q_RB, truth.front().second) * kRadToDeg;
      truth.pop_front();
      ScoredEpoch scored{ns_to_seconds(msg.stamp_ns), error_deg, fdi::to_string(estimate.mode),
                         mask_to_string(estimate.gyros, n)};
      if (error_deg > score.worst_deg) {
        score.worst_deg = error_deg;
        score.worst_time_s = scored.time_s;
      }
      score.series.push_back(std::move(scored));
      ++score.attitudes_scored;
    });
    if (!taken) return taken.error();
    return ok_status();
  };

  tetra_GyroSample sample{};
  tetra_AttitudeReference reference{};
  if (auto s = dds::copy_bounded(sample.unit, unit, "unit"); !s) return s.error();
  if (auto s = dds::copy_bounded(reference.unit, unit, "unit"); !s) return s.error();
  sim::SimEpoch epoch;
  const std::int64_t start = monotonic_ns();
  std::optional<std::int64_t> first_stamp;
  std::int64_t next_progress = start + 1'000'000'000;
  std::uint64_t k = 0;
  while (!stop_requested() && simulator.next(epoch)) {
    if (!first_stamp) first_stamp = epoch.stamp_ns;
    // Pace: epoch at start + (stamp - first)/speed, waiting on the attitude reader meanwhile.
    if (options.speed > 0) {
      const auto due = start + static_cast<std::int64_t>(static_cast<double>(epoch.stamp_ns - *first_stamp) /
                                                         options.speed);
      for (std::int64_t now = monotonic_ns(); now < due && !stop_requested(); now = monotonic_ns()) {
        if (auto s = waitset->wait(std::chrono::nanoseconds(due - now), triggered); !s) return s.error();
        if (auto s = take_attitudes(); !s) return s.error();
      }
    }
    ++k;
    truth.emplace_back(epoch.stamp_ns, epoch.truth_q_RB);
    // The reference first, then the gyros: the service has it when the epoch completes.
    if (epoch.reference_q_RB) {
      reference.stamp_ns = epoch.stamp_ns;
      const auto q = to_wxyz(*epoch.reference_q_RB);
      for (std::size_t i = 0; i < 4; ++i) reference.q_RB[i] = q[i];
      if (auto s = reference_writer->write(reference); !s) return s.error();
    }
    for (int g = 1; g <= n; ++g) {
      if (epoch.present[static_cast<std::size_t>(g - 1)] == 0) continue;  // not delivered (dropout)
      sample.gyro = static_cast<std::uint16_t>(g);
      sample.seq = k;  // the sensor's count: a dropped sample leaves a gap
      sample.stamp_ns = epoch.stamp_ns;
      sample.raw = epoch.raw_V[static_cast<std::size_t>(g - 1)];
      sample.flags = 0;
      if (auto s = gyro_writer->write(sample); !s) return s.error();
    }
    last_stamp = epoch.stamp_ns;
    ++score.epochs_published;
    if (auto s = take_attitudes(); !s) return s.error();
    if (on_progress && monotonic_ns() >= next_progress) {
      score.wall_s = static_cast<double>(monotonic_ns() - start) * 1e-9;
      on_progress(score);
      next_progress += 1'000'000'000;
    }
  }
  score.wall_s = static_cast<double>(monotonic_ns() - start) * 1e-9;
  // The last attitudes: wait (briefly) for the one of the last epoch.
  (void)gyro_writer->wait_for_acks(std::chrono::seconds(2));
  const std::int64_t final_wait = monotonic_ns() + 2'000'000'000;
  while (!stop_requested() && !truth.empty() && truth.back().first == last_stamp) {
    const std::int64_t now = monotonic_ns();
    if (now >= final_wait) break;
    if (auto s = waitset->wait(std::chrono::nanoseconds(final_wait - now), triggered); !s) return s.error();
    if (auto s = take_attitudes(); !s) return s.error();
  }
  return score;
}

int sim_dds_main(sim::Simulator& simulator, const SimDdsOptions& options) {
  dds::ShutdownSignal shutdown;
  const auto progress = [&](const SimDdsScore& s) {
    if (options.quiet) return;
    std::cerr << "tetra sim: " << s.epochs_published << " epochs published, " << s.attitudes_scored
              << " attitudes scored";
    if (!s.series.empty()) {
      std::cerr << "; t = " << fixed(s.series.back().time_s, 2) << " s error now "
                << fixed(s.series.back().error_deg, 5) << " deg, worst " << fixed(s.worst_deg, 5)
                << " deg, mode " << s.series.back().mode << " gyros " << s.series.back().gyros;
    }
    std::cerr << '\n';
  };
  auto score = run_sim_dds(simulator, options, &shutdown, progress);
  if (!score) return report("sim", score.error());
  std::cout << "epochs published: " << score->epochs_published << " in " << fixed(score->wall_s, 2) << " s\n"
            << "attitudes scored: " << score->attitudes_scored << '\n';
  if (score->missing > 0) {
    std::cout << "epochs without an attitude: " << score->missing
              << " (the first at t = " << fixed(score->first_missing_s, 3) << " s)\n";
  }
  if (score->series.empty()) {
    std::cout << "attitude error: no Attitude received for this unit (is `tetra fusion` running?)\n";
    if (!shutdown.requested() && options.wait_readers > 0 && score->epochs_published > 0) {
      // Loud, not silent: a service for another unit (or none) ignored every sample.
      const std::string unit = options.unit.empty() ? simulator.scenario().unit.unit : options.unit;
      return report("sim", failure("--dds: no service accepted the samples of unit '" + unit +
                                   "' (no Attitude came back; check the service's unit against --dds-unit)"));
    }
  } else {
    std::cout << "attitude error now: " << fixed(score->series.back().error_deg, 6) << " deg (mode "
              << score->series.back().mode << ", gyros " << score->series.back().gyros << ")\n"
              << "attitude error worst: " << fixed(score->worst_deg, 6)
              << " deg at t = " << fixed(score->worst_time_s, 3) << " s\n";
  }
  return shutdown.requested() ? kExitFailure : kExitOk;
}

}  // namespace tetra::cli
