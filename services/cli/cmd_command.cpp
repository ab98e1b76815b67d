// tetra command --unit U (reset | exclude N | reinstate N) — an operator command over DDS.
// Waits for a fusion service to match, sends the Command, and waits for its acknowledgement (an
// FdiEvent carrying the command's id), which it prints as a JSON line. Exit 0 when acknowledged,
// 1 when no service answers within --timeout, 2 on bad usage.

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <iostream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/topics.hpp"

namespace tetra::cli {

namespace {
enum Token : std::intptr_t { kMatched = 1, kEvent };
}

int cmd_command(int argc, char** argv) {
  CLI::App app{"Send an operator command to a unit's fusion service and wait for its acknowledgement.",
               "command"};
  std::string unit;
  std::string action;
  int gyro = 0;
  double timeout_s = 5.0;
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  app.add_option("--unit", unit, "the unit to command")->required();
  app.add_option("action", action, "reset, exclude or reinstate")
      ->required()
      ->check(CLI::IsMember({"reset", "exclude", "reinstate"}));
  app.add_option("gyro", gyro, "gyro id (exclude, reinstate)")->check(CLI::Range(1, dds::kMaxGyrosOnWire));
  app.add_option("--timeout", timeout_s, "[s] wait this long for a service and its acknowledgement")
      ->check(CLI::PositiveNumber);
  add_domain_option(app, domain);
  if (auto exit = parse(app, argc, argv)) return *exit;
  if (action == "reset" && gyro != 0) return report("command", bad_input("reset takes no gyro id"));
  if (action != "reset" && gyro == 0)
    return report("command", bad_input(action + " needs a gyro id, e.g. '" + action + " 2'"));

  tetra_Command command{};
  if (auto s = dds::copy_bounded(command.unit, unit, "--unit"); !s) return report("command", s.error());
  command.command_id = (static_cast<std::uint64_t>(wall_ns()) << 16) ^ static_cast<std::uint64_t>(getpid());
  command.kind = action == "reset"     ? tetra_COMMAND_RESET
                 : action == "exclude" ? tetra_COMMAND_EXCLUDE
                                       : tetra_COMMAND_REINSTATE;
  command.gyro = static_cast<std::int16_t>(gyro);

  auto participant = dds::Participant::create(domain, unit);
  if (!participant) return report("command", participant.error());
  auto topics = dds::Topics::create(*participant);
  if (!topics) return report("command", topics.error());
  auto writer = dds::Writer<tetra_Command>::create(*participant, topics->command, dds::command_qos());
  if (!writer) return report("command", writer.error());
  auto events = dds::Reader<tetra_FdiEvent>::create(*participant, topics->event, dds::event_qos());
  if (!events) return report("command", events.error());
  auto waitset = dds::WaitSet::create(*participant);
  if (!waitset) return report("command", waitset.error());
  if (dds_set_status_mask(writer->handle(), DDS_PUBLICATION_MATCHED_STATUS) < 0) {
    return report("command", failure("cannot enable the publication-matched status"));
  }
  if (auto s = waitset->attach(writer->handle(), kMatched); !s) return report("command", s.error());
  auto data = dds::Condition::data_available(events->handle());
  if (!data) return report("command", data.error());
  if (auto s = waitset->attach(data->handle(), kEvent); !s) return report("command", s.error());

  const std::int64_t give_up = monotonic_ns() + static_cast<std::int64_t>(timeout_s * 1e9);
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
    if (ack) {
      std::cout << fdi::to_json(ack->event, std::max(4, static_cast<int>(std::bit_width(ack->event.gyros))))
                << '\n';
      return kExitOk;
    }
    const std::int64_t now = monotonic_ns();
    if (now >= give_up) {
      std::cerr << "tetra command: "
                << (sent ? "no acknowledgement from unit " + unit : "no fusion service found") << " within "
                << timeout_s << " s\n";
      return kExitFailure;
    }
    if (auto s = waitset->wait(std::chrono::nanoseconds(give_up - now), triggered); !s)
      return report("command", s.error());
    std::uint32_t status = 0;
    (void)dds_take_status(writer->handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
  }
}

}  // namespace tetra::cli
