// tetra command --unit U (reset | exclude N [--force] | reinstate N) — an operator command over DDS.
// Waits for a fusion service to match, sends the Command (with the operator's id and the origin),
// and waits for its acknowledgement (an FdiEvent carrying the command's id), which it prints as a
// JSON line. Exit 0 when accepted, 1 when refused or when no service answers within --timeout,
// 2 on bad usage.

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/ground/command_request.hpp"
#include "tetra/ground/command_tracker.hpp"

namespace tetra::cli {

namespace {
enum CommandToken : std::intptr_t { kCommandMatched = 1, kCommandEvent };

//! The login name, for the audit trail when --operator is not given.
std::string login_name() {
  for (const char* var : {"LOGNAME", "USER"}) {
    if (const char* name = std::getenv(var); name != nullptr && *name != '\0') return name;
  }
  return "unknown";
}

//! The acknowledgement as one JSON line: the event (docs/interfaces.md §2.5 form, with "accepted") after the
//! command's id and audit fields.
std::string ack_line(const dds::EventView& ack, int n_gyros) {
  const std::string body = fdi::to_json(ack.event, n_gyros);
  const std::string head = "{\"unit\": " + json_string(ack.unit) + ", \"command_id\": \"" +
                           std::to_string(ack.command_id) + "\", \"command\": \"" +
                           dds::to_string(ack.command.kind) +
                           "\", \"force\": " + (ack.command.force ? "true" : "false") +
                           ", \"operator\": " + json_string(ack.command.operator_id) +
                           ", \"origin\": " + json_string(ack.command.origin);
  return head + (body.size() > 2 ? ", " + body.substr(1) : "}");
}

//! The command's kind from the action word, checked against the gyro id and --force.
Status set_action(ground::CommandRequest& request, const std::string& action) {
  if (action == "reset" && request.gyro != 0) return bad_input("reset takes no gyro id");
  if (action != "reset" && request.gyro == 0)
    return bad_input(action + " needs a gyro id, e.g. '" + action + " 2'");
  if (request.force && action != "exclude") return bad_input("--force applies to exclude only");
  request.kind = action == "reset"     ? tetra_COMMAND_RESET
                 : action == "exclude" ? tetra_COMMAND_EXCLUDE
                                       : tetra_COMMAND_REINSTATE;
  return ok_status();
}

//! Prints the acknowledgement; exit 0 when accepted, 1 (with the reason on stderr) when refused.
int print_ack(const dds::EventView& ack) {
  std::cout << ack_line(ack, std::max(4, static_cast<int>(std::bit_width(ack.event.gyros)))) << '\n';
  if (!ack.event.refused()) return kExitOk;
  std::cerr << "tetra command: refused by unit " << ack.unit << ": " << ack.event.detail << '\n';
  return kExitFailure;
}

std::string host_name() {
  char name[256] = {};
  return gethostname(name, sizeof name - 1) == 0 ? std::string(name) : std::string("localhost");
}
}  // namespace

int cmd_command(int argc, char** argv) {
  CLI::App app{"Send an operator command to a unit's fusion service and wait for its acknowledgement.",
               "command"};
  ground::CommandRequest request;
  std::string action;
  request.operator_id = login_name();
  request.origin = "cli@" + host_name();
  double timeout_s = 5.0;
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  app.add_option("--unit", request.unit, "the unit to command")->required()->check(unit_name_check());
  app.add_option("action", action, "reset, exclude or reinstate")
      ->required()
      ->check(CLI::IsMember({"reset", "exclude", "reinstate"}));
  app.add_option("gyro", request.gyro, "gyro id (exclude, reinstate)")
      ->check(CLI::Range(1, dds::kMaxGyrosOnWire));
  app.add_flag("--force", request.force,
               "exclude even if the remaining gyros could not determine attitude (the unit goes LOST)");
  app.add_option("--operator", request.operator_id,
                 "operator id for the audit trail (default: the login name)");
  app.add_option("--origin", request.origin, "where the command comes from (default: cli@HOSTNAME)");
  app.add_option("--timeout", timeout_s, "[s] wait this long for a service and its acknowledgement")
      ->check(CLI::PositiveNumber);
  add_domain_option(app, domain);
  if (auto exit = parse(app, argc, argv)) return *exit;
  if (auto s = set_action(request, action); !s) return report("command", s.error());
  tetra_Command command{};
  if (auto s = ground::to_wire(request, ground::new_command_id(wall_ns(), getpid()), command); !s)
    return report("command", s.error());
  const std::string& unit = request.unit;

  auto session = dds::Session::open(domain, unit);
  if (!session) return report("command", session.error());
  auto writer = session->writer<tetra_Command>(dds::command_qos());
  if (!writer) return report("command", writer.error());
  auto events = session->reader<tetra_FdiEvent>(dds::event_qos());
  if (!events) return report("command", events.error());
  if (auto s = session->watch_statuses(writer->handle(), DDS_PUBLICATION_MATCHED_STATUS, kCommandMatched); !s)
    return report("command", s.error());
  if (auto s = session->watch_data(events->handle(), kCommandEvent); !s) return report("command", s.error());

  const std::int64_t give_up = monotonic_ns() + seconds_to_ns(timeout_s);
  std::vector<std::intptr_t> triggered;
  bool sent = false;
  for (;;) {
    if (!sent) {
      auto matched = writer->matched_readers();
      if (!matched) return report("command", matched.error());
      if (*matched > 0) {
        if (auto s = writer->write(command); !s) return report("command", s.error());
        sent = true;
      }
    }
    std::optional<dds::EventView> ack;
    auto taken = events->take([&](const tetra_FdiEvent& msg, const dds_sample_info_t&) {
      if (msg.command_id == command.command_id && dds::from_wire(msg.unit) == unit) ack = dds::from_wire(msg);
    });
    if (!taken) return report("command", taken.error());
    if (ack) return print_ack(*ack);
    const std::int64_t now = monotonic_ns();
    if (now >= give_up) {
      std::cerr << "tetra command: "
                << (sent ? "no acknowledgement from unit " + unit : "no fusion service found") << " within "
                << timeout_s << " s\n";
      return kExitFailure;
    }
    if (auto s = session->wait(std::chrono::nanoseconds(give_up - now), triggered); !s)
      return report("command", s.error());
    std::uint32_t status = 0;
    (void)dds_take_status(writer->handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
  }
}

}  // namespace tetra::cli
