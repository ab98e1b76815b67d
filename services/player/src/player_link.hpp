#pragma once
// The player's end of the wire: GyroSample and AttitudeReference writers, an Attitude reader (lockstep and
// the count of attitudes received), and the wait at start-up until the service hears the writer.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/player/log_player.hpp"

namespace tetra::player {

class PlayerLink {
 public:
  //! Creates the entities (the deadline offered: 3 periods of `rate_hz` at `speed`, at 1 in lockstep)
  //! and waits for the readers and the service of `unit`.
  static Result<std::unique_ptr<PlayerLink>> open(const std::string& unit, double rate_hz,
                                                  bool with_reference, const PlayOptions& options,
                                                  dds::ShutdownSignal* shutdown);
  //! The reference first (acknowledged before the samples in lockstep), then the samples delivered (in
  //! lockstep each saying how many the epoch has, dds::promised_samples). A reader behind holds a write
  //! back, never loses it: written again until it is taken, for at most 30 s.
  Status publish(std::int64_t stamp_ns, std::uint64_t seq, std::span<const double> raw,
                 std::span<const std::uint8_t> present, const std::optional<std::array<double, 4>>& ref_wxyz,
                 bool lockstep, std::uint64_t& samples);
  //! Takes the attitudes of this unit received so far; returns the newest stamp seen (or the previous).
  Status take_attitudes(std::uint64_t& count, std::int64_t& newest_stamp_ns);
  //! Blocks until data arrives, a shutdown is requested or the monotonic time `until_ns` passes.
  Status wait_until(std::int64_t until_ns);
  bool stop_requested() const { return shutdown_ != nullptr && shutdown_->requested(); }
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

  std::string unit_;
  dds::Session session_;
  dds::Writer<tetra_GyroSample> gyro_;
  dds::Writer<tetra_AttitudeReference> reference_;
  dds::Reader<tetra_Attitude> attitude_;
  dds::ShutdownSignal* shutdown_ = nullptr;
  std::vector<std::intptr_t> triggered_;
  tetra_GyroSample sample_{};
  tetra_AttitudeReference reference_msg_{};
};

}  // namespace tetra::player
