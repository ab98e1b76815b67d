#pragma once
// The two-person rule (docs/ground.md, "Two-person rule"): a command that may leave a unit unable to
// determine attitude (an exclusion with `force`) is held until a second commander — another operator
// than the one who asked — approves it within a time limit; only then is it sent. Bounded: at most
// `max_pending` held at once.

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tetra/ground/command_request.hpp"

namespace tetra::ground {

struct PendingCommand {
  std::string id;               //!< random, given to the requester and listed for the approvers
  CommandRequest request;       //!< as asked (operator_id: the requester)
  std::int64_t expires_ns = 0;  //!< [ns, steady clock]
};

struct ApprovalOutcome {
  int status = 200;  //!< 200 approved; 403 the requester's own; 404 unknown, expired or already taken
  std::string message;
  std::optional<PendingCommand> command;  //!< when approved: to send now
};

class Approvals {
 public:
  explicit Approvals(double timeout_s = 120.0, std::size_t max_pending = 16);
  //! Holds the request; its id, or nullopt when `max_pending` are held already.
  std::optional<std::string> add(const CommandRequest& request, std::int64_t now_ns);
  //! `approver` approves `id`: the command when it is another operator's and still held.
  ApprovalOutcome approve(const std::string& id, const std::string& approver, std::int64_t now_ns);
  //! The command held under `id`, if any.
  std::optional<PendingCommand> find(const std::string& id, std::int64_t now_ns);
  //! The held commands: [{id, unit, command, operator, expires_in_s}].
  nlohmann::json list(std::int64_t now_ns);
  double timeout_s() const { return timeout_s_; }

 private:
  void expire(std::int64_t now_ns);
  double timeout_s_;
  std::size_t max_pending_;
  std::mutex mutex_;
  std::vector<PendingCommand> pending_;
};

//! "reset", "exclude gyro 3 force", ...: a command as the audit and the log name it.
std::string describe_command(const CommandRequest& request);

}  // namespace tetra::ground
