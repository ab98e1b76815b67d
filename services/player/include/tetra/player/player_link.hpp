#pragma once
// The player's end of the wire: GyroSample and AttitudeReference writers, an Attitude reader (lockstep and
// the count of attitudes received), and the wait at start-up until the service hears the writer. Used by
// `tetra play` and by the Python package's tetra.dds (python/src/bind_dds.cpp).

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/dds/one_writer.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/player/log_player.hpp"

namespace tetra::player {

class PlayerLink {
 public:
  //! Asked while the link waits (at least every kStopPollEvery): true stops the wait, as a shutdown
  //! signal does (an interpreter's pending KeyboardInterrupt).
  using StopPoll = std::function<bool()>;
  static constexpr std::int64_t kStopPollEvery_ns = 10'000'000;
  using AttitudeSink = std::function<void(const fdi::AttitudeEstimate&)>;

  //! Creates the entities (the deadline offered: 3 periods of `rate_hz` at `speed`, at 1 in lockstep)
  //! and waits for the readers and the service of `unit`.
  static Result<std::unique_ptr<PlayerLink>> open(const std::string& unit, double rate_hz,
                                                  bool with_reference, const PlayOptions& options,
                                                  dds::ShutdownSignal* shutdown, StopPoll stop = {});
  //! The reference first, then the samples delivered (in lockstep each saying how many the epoch has,
  //! dds::promised_samples, and that its reference was written: the service waits for both). A reader behind
  //! holds a write back, never loses it: written again until it is taken, for at most 30 s.
  Status publish(std::int64_t stamp_ns, std::uint64_t seq, std::span<const double> raw,
                 std::span<const std::uint8_t> present, const std::optional<std::array<double, 4>>& ref_wxyz,
                 bool lockstep, std::uint64_t& samples);
  //! Takes the attitudes of this unit received so far; returns the newest stamp seen (or the previous).
  Status take_attitudes(std::uint64_t& count, std::int64_t& newest_stamp_ns);
  //! Takes the attitudes of this unit received so far, in order, each handed to `on_attitude`; after
  //! require_one_attitude_writer(), an error when they come from a second writer (two services of the unit,
  //! or one restarted: a lockstep run would mix their estimates).
  Status take_attitudes(const AttitudeSink& on_attitude);
  void require_one_attitude_writer() { attitude_writer_.require(); }
  //! Lockstep: takes attitudes (each to `on_attitude`, the newest stamp into `newest_stamp_ns`) until one
  //! stamped `stamp_ns` or later has come, `timeout_ns` passes or a stop is asked; false if none came.
  Result<bool> wait_for_stamp(std::int64_t stamp_ns, std::int64_t timeout_ns, std::int64_t& newest_stamp_ns,
                              const AttitudeSink& on_attitude);
  //! Blocks until data arrives, a shutdown is requested or the monotonic time `until_ns` passes.
  Status wait_until(std::int64_t until_ns);
  bool stop_requested() const {
    return (shutdown_ != nullptr && shutdown_->requested()) || (stop_ && stop_());
  }
  void set_stop_poll(StopPoll stop) { stop_ = std::move(stop); }
  //! Waits (up to 2 s) until the samples written are acknowledged.
  void wait_for_acks();

 private:
  PlayerLink(std::string unit, dds::Session session, dds::Writer<tetra_GyroSample> gyro,
             dds::Writer<tetra_AttitudeReference> reference, dds::Reader<tetra_Attitude> attitude)
      : unit_(std::move(unit)),
        session_(std::move(session)),
        gyro_(std::move(gyro)),
        reference_(std::move(reference)),
        attitude_(std::move(attitude)) {}
  Status wait_for_readers(const PlayOptions& options, bool with_reference);
  Status wait_for_service(const PlayOptions& options);
  //! Writes sample_, again while a reader holds the writer back (KEEP_ALL history full).
  Status write_held();
  //! How long a wait until the monotonic `until_ns` may block: at most kStopPollEvery_ns with a stop poll.
  std::chrono::nanoseconds wait_for(std::int64_t until_ns) const;

  std::string unit_;
  dds::Session session_;
  dds::Writer<tetra_GyroSample> gyro_;
  dds::Writer<tetra_AttitudeReference> reference_;
  dds::Reader<tetra_Attitude> attitude_;
  dds::ShutdownSignal* shutdown_ = nullptr;
  StopPoll stop_;
  dds::OneWriter attitude_writer_;  //!< the Attitude writer of this unit (another: an error once required)
  std::vector<std::intptr_t> triggered_;
  tetra_GyroSample sample_{};
  tetra_AttitudeReference reference_msg_{};
};

}  // namespace tetra::player
