#pragma once
// The simulator's end of the wire (`tetra sim --dds`, open or closed loop): the GyroSample and
// AttitudeReference writers, the Attitude reader, and the wait at start-up for the service (and any
// other gyro reader) to hear the writer before the first sample is published.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/one_writer.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/dds_tools/sim_dds.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::dds_tools {

class SimDdsLink {
 public:
  //! Creates the entities and waits for `options.wait_readers` gyro readers (see src/sim_dds_link.cpp).
  static Result<std::unique_ptr<SimDdsLink>> open(const std::string& unit, double rate_hz,
                                                  const SimDdsOptions& options,
                                                  const dds::ShutdownSignal* shutdown);
  //! Publishes one epoch: the reference first, then the gyro samples delivered, with sequence number `k`;
  //! with a reference, each sample carries dds::kGyroFlagReferenceWritten, so the service holds the
  //! epoch until the reference is in (the two topics have no common delivery order), with no wait here.
  Status publish(const sim::SimEpoch& epoch, std::uint64_t k);
  //! Takes the Attitude samples of this unit received so far, in order; after
  //! require_one_attitude_writer(), an error when they come from more than one writer (two services of
  //! the unit, or one restarted: a lockstep run would mix them).
  Status take_attitudes(const std::function<void(const fdi::AttitudeEstimate&)>& on_attitude);
  //! Blocks until data arrives on the Attitude reader, a shutdown is requested or the monotonic
  //! time `until_ns` passes.
  Status wait_until(std::int64_t until_ns);
  void require_one_attitude_writer() { attitude_writer_.require(); }
  bool stop_requested() const { return shutdown_ != nullptr && shutdown_->requested(); }
  //! Waits (up to 2 s) until the samples written are acknowledged.
  void wait_for_acks();
  //! For more readers on the same participant (a campaign reads the FdiEvent and Health topics too).
  const dds::Participant& participant() const { return session_.participant(); }
  const dds::Topics& topics() const { return session_.topics(); }

 private:
  SimDdsLink(std::string unit, dds::Session session, dds::Writer<tetra_GyroSample> gyro_writer,
             dds::Writer<tetra_AttitudeReference> reference_writer,
             dds::Reader<tetra_Attitude> attitude_reader)
      : unit_(std::move(unit)),
        session_(std::move(session)),
        gyro_writer_(std::move(gyro_writer)),
        reference_writer_(std::move(reference_writer)),
        attitude_reader_(std::move(attitude_reader)) {}
  Status wait_for_readers(const SimDdsOptions& options);
  Status wait_for_service(const SimDdsOptions& options);
  //! "; N GyroSample reader(s) refused this writer's QoS: deadline (…)" when a reader did not match, else "".
  std::string incompatible_readers_note() const;

  std::string unit_;
  dds::Session session_;
  dds::Writer<tetra_GyroSample> gyro_writer_;
  dds::Writer<tetra_AttitudeReference> reference_writer_;
  dds::Reader<tetra_Attitude> attitude_reader_;
  const dds::ShutdownSignal* shutdown_ = nullptr;
  std::vector<std::intptr_t> triggered_;
  dds::OneWriter attitude_writer_;  //!< the Attitude writer of this unit (another: an error in lockstep)
  tetra_GyroSample sample_{};
  tetra_AttitudeReference reference_{};
};

}  // namespace tetra::dds_tools
