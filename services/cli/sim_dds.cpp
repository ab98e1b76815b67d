#include "sim_dds.hpp"

#include <deque>
#include <iostream>

#include "cli_common.hpp"
#include "dds_common.hpp"
#include "sim_dds_link.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"

namespace tetra::cli {

void add_sim_dds_options(CLI::App& app, SimDdsOptions& options) {
  app.add_flag("--dds", options.enabled,
               "publish on DDS (GyroSample, AttitudeReference) instead of writing files, "
               "and score the Attitude received against the truth");
  app.add_option("--speed", options.speed,
                 "--dds: 1 = real time, X = X times faster, 0 = as fast as possible (at most 1e6)")
      ->check(number_in(0.0, 1.0e6))
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {  // a slower clock than 1/1000 would overflow the pacing
            const auto v = parse_decimal(text);
            return v && *v > 0.0 && *v < 1e-3
                       ? "'" + text + "' must be 0 (as fast as possible) or at least 0.001"
                       : std::string();
          },
          "", "0 or at least 0.001"));
  app.add_option("--dds-unit", options.unit, "--dds: the unit's key on the wire (default: the unit's name)")
      ->check(unit_name_check());
  app.add_option("--wait-readers", options.wait_readers, "--dds: gyro readers to wait for before publishing")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wait-timeout", options.wait_timeout_s,
                 "[s] --dds: how long to wait for them (at most a day)")
      ->check(number_in(0.0, 86400.0, true));
  add_domain_option(app, options.domain);
}

namespace {

//! Scores each Attitude received against the truth of its epoch.
class Scorer {
 public:
  explicit Scorer(int n_gyros) : n_(n_gyros) {}
  //! An epoch published with its truth.
  void published(const sim::SimEpoch& epoch) {
    truth_.emplace_back(epoch.stamp_ns, epoch.truth_q_RB);
    last_stamp_ = epoch.stamp_ns;
    ++score_.epochs_published;
  }
  Status take(SimDdsLink& link) {
    return link.take_attitudes([&](const fdi::AttitudeEstimate& estimate) { score(estimate); });
  }
  //! The last epoch published still waits for its attitude.
  bool awaiting_last() const { return !truth_.empty() && truth_.back().first == last_stamp_; }
  SimDdsScore& result() { return score_; }

 private:
  void score(const fdi::AttitudeEstimate& estimate) {
    while (!truth_.empty() && truth_.front().first < estimate.stamp_ns) {
      if (score_.missing == 0) score_.first_missing_s = ns_to_seconds(truth_.front().first);
      ++score_.missing;  // an epoch published, but no attitude for it
      truth_.pop_front();
    }
    if (truth_.empty() || truth_.front().first != estimate.stamp_ns) return;
    const double error_deg = angle_between(estimate.q_RB, truth_.front().second) * kRadToDeg;
    truth_.pop_front();
    ScoredEpoch scored{ns_to_seconds(estimate.stamp_ns), error_deg, fdi::to_string(estimate.mode),
                       mask_to_string(estimate.gyros, n_)};
    if (error_deg > score_.worst_deg) {
      score_.worst_deg = error_deg;
      score_.worst_time_s = scored.time_s;
    }
    score_.series.push_back(std::move(scored));
    ++score_.attitudes_scored;
  }

  int n_;
  SimDdsScore score_;
  std::deque<std::pair<std::int64_t, Quaternion>> truth_;  // (stamp, q_RB) of epochs not yet scored
  std::int64_t last_stamp_ = 0;
};

//! Until local time `due_ns` (or a stop), scoring the attitudes that arrive meanwhile.
Status wait_scoring(SimDdsLink& link, Scorer& scorer, std::int64_t due_ns) {
  for (std::int64_t now = monotonic_ns(); now < due_ns && !link.stop_requested(); now = monotonic_ns()) {
    if (auto s = link.wait_until(due_ns); !s) return s;
    if (auto s = scorer.take(link); !s) return s;
  }
  return ok_status();
}

}  // namespace

Result<SimDdsScore> run_sim_dds(sim::Simulator& simulator, const SimDdsOptions& options,
                                const dds::ShutdownSignal* shutdown,
                                const std::function<void(const SimDdsScore&)>& on_progress) {
  const std::string unit = options.unit.empty() ? simulator.scenario().unit.unit : options.unit;
  auto opened = SimDdsLink::open(unit, simulator.scenario().rate_hz, options, shutdown);
  if (!opened) return opened.error();
  SimDdsLink& link = *opened.value();
  Scorer scorer(simulator.gyro_count());
  sim::SimEpoch epoch;
  const std::int64_t start = monotonic_ns();
  std::optional<std::int64_t> first_stamp;
  std::int64_t next_progress = start + 1'000'000'000;
  std::uint64_t k = 0;
  while (!link.stop_requested() && simulator.next(epoch)) {
    if (!first_stamp) first_stamp = epoch.stamp_ns;
    // Pace: epoch at start + (stamp - first)/speed, scoring attitudes meanwhile.
    if (options.speed > 0) {
      const double offset_ns = static_cast<double>(epoch.stamp_ns - *first_stamp) / options.speed;
      if (auto s = wait_scoring(link, scorer, start + static_cast<std::int64_t>(offset_ns)); !s)
        return s.error();
    }
    scorer.published(epoch);
    if (auto s = link.publish(epoch, ++k); !s) return s.error();
    if (auto s = scorer.take(link); !s) return s.error();
    if (on_progress && monotonic_ns() >= next_progress) {
      scorer.result().wall_s = ns_to_seconds(monotonic_ns() - start);
      on_progress(scorer.result());
      next_progress += 1'000'000'000;
    }
  }
  scorer.result().wall_s = ns_to_seconds(monotonic_ns() - start);
  // The last attitudes: wait (briefly) for the one of the last epoch.
  link.wait_for_acks();
  const std::int64_t final_wait = monotonic_ns() + 2'000'000'000;
  while (!link.stop_requested() && scorer.awaiting_last() && monotonic_ns() < final_wait) {
    if (auto s = link.wait_until(final_wait); !s) return s.error();
    if (auto s = scorer.take(link); !s) return s.error();
  }
  return std::move(scorer.result());
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
