#pragma once
// DDS -> ground store, and commands from the browser -> DDS (`tetra ground`, docs/ground.md).
// run() takes Health, FdiEvent and Attitude into the store on the calling thread and refreshes the
// units' link states; send() may be called from any thread (the HTTP server's).

#include <chrono>
#include <mutex>

#include "tetra/ground/command_request.hpp"
#include "tetra/ground/command_tracker.hpp"
#include "tetra/ground/ground_readers.hpp"
#include "tetra/ground/store.hpp"

namespace tetra::ground {

class GroundBridge {
 public:
  GroundBridge(GroundReaders readers, GroundStore& store) : readers_(std::move(readers)), store_(store) {}

  //! Serves until `shutdown` is requested (or a DDS failure).
  Status run(const dds::ShutdownSignal& shutdown);
  //! Sends `request` and waits up to `timeout` for the service's acknowledgement.
  Result<dds::EventView> send(const CommandRequest& request, std::chrono::milliseconds timeout);

 private:
  Status take_all(std::int64_t now_ns);

  GroundReaders readers_;
  GroundStore& store_;
  CommandTracker tracker_;
  std::mutex write_mutex_;
};

}  // namespace tetra::ground
