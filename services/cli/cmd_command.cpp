// tetra command --unit U (reset | exclude N [--force] | reinstate N) — an operator command over DDS.
// Sends the command and waits for its acknowledgement (tetra/dds_tools/command.hpp), which it prints as a
// JSON line. Exit 0 when accepted, 1 when refused or when no service answers within --timeout,
// 2 on bad usage.

#include <unistd.h>

#include <cstdlib>
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/dds_tools/command.hpp"

namespace tetra::cli {

namespace {

//! The login name, for the audit trail when --operator is not given.
std::string login_name() {
  for (const char* var : {"LOGNAME", "USER"}) {
    if (const char* name = std::getenv(var); name != nullptr && *name != '\0') return name;
  }
  return "unknown";
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
  auto ack = dds_tools::send_command({request, action, timeout_s, domain});
  if (!ack)
    return report("command", ack.error(), {{dds_tools::kSubjectForce, "--force applies to exclude only"}});
  std::cout << dds_tools::command_ack_line(*ack) << '\n';
  if (!ack->event.refused()) return kExitOk;
  std::cerr << "tetra command: refused by unit " << ack->unit << ": " << ack->event.detail << '\n';
  return kExitFailure;
}

}  // namespace tetra::cli
