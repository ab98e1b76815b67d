// The ground's commands over HTTP (docs/ground.md, "Commands", "Two-person rule"): a commander's
// command is sent and its acknowledgement returned; a forced exclusion (it may leave the unit unable to
// determine attitude) is held until another commander approves it. Every decision is audited.

#include <spdlog/spdlog.h>

#include "tetra/ground/encode.hpp"
#include "tetra/ground/http_api.hpp"
#include "tetra/ground/strict_json.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {

namespace {

//! The audit record of a decision about a command.
AuditRecord command_record(const char* decision, const char* outcome, int status, const std::string& user,
                           const std::string& role, const CommandRequest& request, std::string reason) {
  AuditRecord r;
  r.decision = decision;
  r.outcome = outcome;
  r.status = status;
  r.operator_id = user;
  r.role = role;
  r.unit = request.unit;
  r.command = describe_command(request);
  r.reason = std::move(reason);
  return r;
}

}  // namespace

HttpResponse GroundServer::command(const HttpRequest& req, const Session& session) {
  const std::string role = to_string(session.role);
  if (session.role != Role::kCommander)
    return refuse(req, 403, "the role viewer may not command", session.user, role);
  auto request = parse_command_request(req.body, session.user, "ground@" + req.remote_addr);
  if (!request) return refuse(req, 400, request.error().message, session.user, role);
  if (const auto no = permissions_.refusal(session.user, role, *request); !no.empty())
    return refuse(req, 403, no, session.user, role);
  // Under --no-auth there is one operator only: no second one to approve.
  if (!request->force || config_.no_auth) return send_command(req, *request, role, "");
  const auto id = approvals_.add(*request, steady_now_ns());
  if (!id) return refuse(req, 503, "16 commands wait for approval already: try again", session.user, role);
  audit(req, command_record("command", "pending", 202, session.user, role, *request,
                            "held for a second commander's approval (" + *id + ")"));
  return json_reply(202, {{"pending", *id},
                          {"unit", request->unit},
                          {"unit_id", unit_id(request->unit)},
                          {"command", describe_command(*request)},
                          {"operator", session.user},
                          {"approve_within_s", approvals_.timeout_s()}});
}

HttpResponse GroundServer::approve(const HttpRequest& req, const Session& session) {
  const std::string role = to_string(session.role);
  if (session.role != Role::kCommander)
    return refuse(req, 403, "the role viewer may not approve", session.user, role);
  auto body = parse_strict_json(req.body);
  if (!body || !body->is_object() || body->size() != 1 || !(*body)["id"].is_string())
    return refuse(req, 400, "approve: a JSON object {\"id\"}", session.user, role);
  // The approver needs the permission for the command too: it is sent on both operators' word.
  const std::string id = (*body)["id"].get<std::string>();
  if (const auto held = approvals_.find(id, steady_now_ns())) {
    if (const auto no = permissions_.refusal(session.user, role, held->request); !no.empty())
      return refuse(req, 403, no, session.user, role);
  }
  auto outcome = approvals_.approve(id, session.user, steady_now_ns());
  if (!outcome.command) return refuse(req, outcome.status, outcome.message, session.user, role);
  const CommandRequest& request = outcome.command->request;
  audit(req, command_record("approval", "accepted", 200, session.user, role, request,
                            "approves " + request.operator_id + "'s command (" + outcome.command->id + ")"));
  return send_command(req, request, "commander", session.user);
}

HttpResponse GroundServer::send_command(const HttpRequest& req, const CommandRequest& request,
                                        const std::string& role, const std::string& approved_by) {
  if (commands_waiting_.fetch_add(1) >= config_.commands_in_flight) {
    commands_waiting_.fetch_sub(1);
    return refuse(req, 503, "other commands are waiting for their acknowledgement: try again",
                  request.operator_id, role);
  }
  auto ack = send_(request);
  commands_waiting_.fetch_sub(1);
  AuditRecord r = command_record("command", "", 0, request.operator_id, role, request, "");
  const std::string approval = approved_by.empty() ? "" : " (approved by " + approved_by + ")";
  if (!ack) {
    r.outcome = "unanswered";
    r.status = 504;
    r.reason = "no acknowledgement: " + ack.error().message + approval;
    audit(req, std::move(r));
    return error_reply(504, ack.error().message);
  }
  r.outcome = ack->event.refused() ? "refused" : "accepted";
  r.decided_by = "service";
  r.status = 200;
  r.reason = ack->event.detail + approval;
  audit(req, std::move(r));
  auto answer = ack_json(*ack, 16);
  if (!approved_by.empty()) answer["approved_by"] = approved_by;
  return json_reply(200, answer);
}

}  // namespace tetra::ground
