#include "tetra/ground/approvals.hpp"

#include <algorithm>

#include "tetra/ground/operators.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {

std::string describe_command(const CommandRequest& request) {
  return std::string(request.kind == tetra_COMMAND_RESET     ? "reset"
                     : request.kind == tetra_COMMAND_EXCLUDE ? "exclude"
                                                             : "reinstate") +
         (request.gyro != 0 ? " gyro " + std::to_string(request.gyro) : "") + (request.force ? " force" : "");
}

Approvals::Approvals(double timeout_s, std::size_t max_pending)
    : timeout_s_(timeout_s), max_pending_(max_pending) {}

void Approvals::expire(std::int64_t now_ns) {
  pending_.erase(std::remove_if(pending_.begin(), pending_.end(),
                                [now_ns](const PendingCommand& p) { return now_ns >= p.expires_ns; }),
                 pending_.end());
}

std::optional<std::string> Approvals::add(const CommandRequest& request, std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  expire(now_ns);
  if (pending_.size() >= max_pending_) return std::nullopt;
  PendingCommand p;
  p.id = random_hex(8);
  p.request = request;
  p.expires_ns = now_ns + static_cast<std::int64_t>(timeout_s_ * 1e9);
  pending_.push_back(p);
  return p.id;
}

ApprovalOutcome Approvals::approve(const std::string& id, const std::string& approver, std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  expire(now_ns);
  const auto it = std::find_if(pending_.begin(), pending_.end(),
                               [&](const PendingCommand& p) { return same_secret(p.id, id); });
  ApprovalOutcome out;
  if (it == pending_.end()) {
    out.status = 404;
    out.message = "no such command waiting for approval (approved already, or older than " +
                  std::to_string(static_cast<int>(timeout_s_)) + " s)";
  } else if (it->request.operator_id == approver) {
    out.status = 403;
    out.message = "a second operator must approve: " + approver + " asked for it";
  } else {
    out.command = *it;
    pending_.erase(it);
  }
  return out;
}

std::optional<PendingCommand> Approvals::find(const std::string& id, std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  expire(now_ns);
  for (const auto& p : pending_) {
    if (same_secret(p.id, id)) return p;
  }
  return std::nullopt;
}

nlohmann::json Approvals::list(std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  expire(now_ns);
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : pending_) {
    out.push_back({{"id", p.id},
                   {"unit", p.request.unit},
                   {"unit_id", unit_id(p.request.unit)},
                   {"command", describe_command(p.request)},
                   {"operator", p.request.operator_id},
                   {"expires_in_s", static_cast<double>(p.expires_ns - now_ns) / 1e9}});
  }
  return out;
}

}  // namespace tetra::ground
