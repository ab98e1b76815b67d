#include "tetra/dds_tools/sim_dds.hpp"

#include <deque>

#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/dds_tools/sim_dds_link.hpp"

namespace tetra::dds_tools {

using dds::monotonic_ns;

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

}  // namespace tetra::dds_tools
