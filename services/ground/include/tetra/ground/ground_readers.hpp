#pragma once
// The ground's side of DDS, shared by `tetra monitor` and `tetra ground`: Health, FdiEvent and
// Attitude readers of every unit (or one), a waitset over them, the shutdown guard, and the
// Command writer. Each take_*() hands samples with their DDS source timestamp (UTC) to a callback;
// take_health() also reports when a unit's Health writer lost its liveliness.

#include <functional>
#include <optional>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/shutdown.hpp"

namespace tetra::ground {

enum ReaderToken : std::intptr_t { kHealthToken = 1, kEventToken, kAttitudeToken, kShutdownToken };

class GroundReaders {
 public:
  //! Opens everything on `domain`; `unit` "" reads every unit. `shutdown` gets the waitset's guard.
  static Result<GroundReaders> open(dds_domainid_t domain, const std::string& unit,
                                    dds::ShutdownSignal& shutdown);

  Status take_health(const std::function<void(dds::HealthView&&, std::int64_t utc_ns)>& on_health,
                     const std::function<void(const std::string& unit)>& on_writer_lost) const;
  Status take_events(const std::function<void(dds::EventView&&, std::int64_t utc_ns)>& on_event) const;
  Status take_attitudes(const std::function<void(const std::string& unit, fdi::AttitudeEstimate&&,
                                                 std::int64_t utc_ns)>& on_attitude) const;
  //! Waits up to `timeout` for data or the shutdown guard.
  Status wait(std::chrono::nanoseconds timeout, std::vector<std::intptr_t>& triggered) const;
  //! Health writers matched (fusion services heard).
  Result<std::uint32_t> health_writers() const { return health_->matched_writers(); }
  const dds::Writer<tetra_Command>& command_writer() const { return *command_; }

 private:
  GroundReaders() = default;
  std::optional<dds::Session> session_;
  std::optional<dds::Reader<tetra_Health>> health_;
  std::optional<dds::Reader<tetra_FdiEvent2>> event_;
  std::optional<dds::Reader<tetra_Attitude>> attitude_;
  std::optional<dds::Writer<tetra_Command>> command_;
};

}  // namespace tetra::ground
