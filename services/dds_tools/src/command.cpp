// Operator commands over DDS (tetra/dds_tools/command.hpp).
#include "tetra/dds_tools/command.hpp"

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <optional>
#include <sstream>
#include <vector>

#include "tetra/core/json.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/ground/command_tracker.hpp"

namespace tetra::dds_tools {

namespace {

enum CommandToken : std::intptr_t { kCommandMatched = 1, kCommandEvent };

std::string quoted_json(const std::string& text) {
  std::string out;
  append_json_string(out, text);
  return out;
}

//! The command's kind from the action word, checked against the gyro id and force.
Status set_action(ground::CommandRequest& request, const std::string& action) {
  if (action != "reset" && action != "exclude" && action != "reinstate")
    return bad_input("action '" + action + "': expected reset, exclude or reinstate");
  if (action == "reset" && request.gyro != 0) return bad_input("reset takes no gyro id");
  if (action != "reset" && request.gyro == 0)
    return bad_input(action + " needs a gyro id, e.g. '" + action + " 2'");
  if (request.force && action != "exclude")
    return bad_input(ErrorSubject(kSubjectForce), "applies to exclude only");
  request.kind = action == "reset"     ? tetra_COMMAND_RESET
                 : action == "exclude" ? tetra_COMMAND_EXCLUDE
                                       : tetra_COMMAND_REINSTATE;
  return ok_status();
}

}  // namespace

std::string command_ack_line(const dds::EventView& ack) {
  const int n_gyros = std::max(4, static_cast<int>(std::bit_width(ack.event.gyros)));
  const std::string body = fdi::to_json(ack.event, n_gyros);
  const std::string head = "{\"unit\": " + quoted_json(ack.unit) + ", \"command_id\": \"" +
                           std::to_string(ack.command_id) + "\", \"command\": \"" +
                           dds::to_string(ack.command.kind) +
                           "\", \"force\": " + (ack.command.force ? "true" : "false") +
                           ", \"operator\": " + quoted_json(ack.command.operator_id) +
                           ", \"origin\": " + quoted_json(ack.command.origin);
  return head + (body.size() > 2 ? ", " + body.substr(1) : "}");
}

Result<dds::EventView> send_command(const CommandOptions& o) {
  ground::CommandRequest request = o.request;
  if (auto s = set_action(request, o.action); !s) return s.error();
  tetra_Command command{};
  if (auto s = ground::to_wire(request, ground::new_command_id(dds::wall_ns(), getpid()), command); !s)
    return s.error();
  const std::string& unit = request.unit;

  auto session = dds::Session::open(o.domain, unit);
  if (!session) return session.error();
  auto writer = session->writer<tetra_Command>(dds::command_qos());
  if (!writer) return writer.error();
  auto events = session->reader<tetra_FdiEvent2>(dds::event_qos());
  if (!events) return events.error();
  if (auto s = session->watch_statuses(writer->handle(), DDS_PUBLICATION_MATCHED_STATUS, kCommandMatched); !s)
    return s.error();
  if (auto s = session->watch_data(events->handle(), kCommandEvent); !s) return s.error();

  const std::int64_t give_up = dds::monotonic_ns() + seconds_to_ns(o.timeout_s);
  std::vector<std::intptr_t> triggered;
  bool sent = false;
  for (;;) {
    if (!sent) {
      auto matched = writer->matched_readers();
      if (!matched) return matched.error();
      if (*matched > 0) {
        if (auto s = writer->write(command); !s) return s.error();
        sent = true;
      }
    }
    std::optional<dds::EventView> ack;
    auto taken = events->take([&](const tetra_FdiEvent2& msg, const dds_sample_info_t&) {
      if (msg.command_id == command.command_id && dds::from_wire(msg.unit) == unit) ack = dds::from_wire(msg);
    });
    if (!taken) return taken.error();
    if (ack) return *ack;
    const std::int64_t now = dds::monotonic_ns();
    if (now >= give_up) {
      std::ostringstream why;
      why << (sent ? "no acknowledgement from unit " + unit : "no fusion service found") << " within "
          << o.timeout_s << " s";
      return failure(why.str());
    }
    if (auto s = session->wait(std::chrono::nanoseconds(give_up - now), triggered); !s) return s.error();
    std::uint32_t status = 0;
    (void)dds_take_status(writer->handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
  }
}

}  // namespace tetra::dds_tools
