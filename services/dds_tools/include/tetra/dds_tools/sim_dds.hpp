#pragma once
// `tetra sim --dds`: the simulated unit on the wire. Publishes each epoch's gyro samples (and the
// attitude reference) in real time or `--speed` times faster, subscribes to the unit's Attitude and
// scores it live against the truth (error now, worst, at the end). Also used by `tetra demo`.

#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/sim/simulator.hpp"

namespace tetra::dds {
class ShutdownSignal;
}

namespace tetra::dds_tools {

struct SimDdsOptions {
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  std::string unit;              //!< DDS key; empty: the simulated unit's name
  double speed = 1.0;            //!< 1 = real time, 10 = ten times faster, 0 = as fast as possible
  int wait_readers = 1;          //!< gyro readers to wait for before publishing
  double wait_timeout_s = 10.0;  //!< [s] give up waiting for them
};

//! Attitude error [deg] at one epoch: angle between the received estimate and the truth.
struct ScoredEpoch {
  double time_s = 0.0;
  double error_deg = 0.0;
  std::string mode;
  std::string gyros;
};

struct SimDdsScore {
  std::uint64_t epochs_published = 0;
  std::uint64_t attitudes_scored = 0;  //!< received and matched to a truth epoch
  std::uint64_t missing = 0;           //!< epochs before a received attitude that got none
  double first_missing_s = 0.0;        //!< [s] the first of them
  double wall_s = 0.0;                 //!< [s] publishing time
  double worst_deg = 0.0;
  double worst_time_s = 0.0;
  //! Every scored epoch, in order. A deque: an hour at 100 Hz never moves the whole series at once
  //! (a vector doubling its 30 MB would stall the simulator for tens of milliseconds).
  std::deque<ScoredEpoch> series;
};

//! Runs the simulator on the wire until its end (or a shutdown signal). `on_progress` is called
//! about once per wall-clock second with the score so far.
Result<SimDdsScore> run_sim_dds(sim::Simulator& simulator, const SimDdsOptions& options,
                                const dds::ShutdownSignal* shutdown,
                                const std::function<void(const SimDdsScore&)>& on_progress = {});

}  // namespace tetra::dds_tools
