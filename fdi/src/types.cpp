#include "tetra/fdi/types.hpp"

#include <array>
#include <cmath>

#include "tetra/core/csv.hpp"
#include "tetra/core/json.hpp"
#include "tetra/core/units.hpp"

namespace tetra::fdi {

const char* to_string(Mode mode) {
  switch (mode) {
    case Mode::kNominal:
      return "NOMINAL";
    case Mode::kDegraded:
      return "DEGRADED";
    case Mode::kSuspect:
      return "SUSPECT";
    case Mode::kLost:
      return "LOST";
  }
  return "LOST";
}

namespace {
constexpr std::array<const char*, 10> kKindNames = {"none",  "bias",  "ramp",    "scale",   "stuck",
                                                    "noise", "spike", "dropout", "invalid", "unknown"};
}  // namespace

const char* to_string(FaultKind kind) {
  const auto i = static_cast<std::size_t>(kind);
  return i < kKindNames.size() ? kKindNames[i] : "unknown";
}

std::optional<FaultKind> fault_kind_from_string(std::string_view text) {
  for (std::size_t i = 0; i < kKindNames.size(); ++i) {
    if (text == kKindNames[i]) return static_cast<FaultKind>(i);
  }
  return std::nullopt;
}

const char* to_string(EventType type) {
  switch (type) {
    case EventType::kDetected:
      return "detected";
    case EventType::kIsolated:
      return "isolated";
    case EventType::kUnisolated:
      return "unisolated";
    case EventType::kReconfigured:
      return "reconfigured";
    case EventType::kCleared:
      return "cleared";
    case EventType::kLost:
      return "lost";
    case EventType::kCommand:
      return "command";
  }
  return "command";
}

const char* to_string(GyroState state) {
  switch (state) {
    case GyroState::kOk:
      return "ok";
    case GyroState::kAbsent:
      return "absent";
    case GyroState::kInvalid:
      return "invalid";
    case GyroState::kSuspect:
      return "suspect";
    case GyroState::kExcluded:
      return "excluded";
  }
  return "ok";
}

namespace {

void append_gyro_list(std::string& out, GyroMask mask, int n_gyros) {
  out += '[';
  bool first = true;
  for (int id = 1; id <= n_gyros; ++id) {
    if (!has_gyro(mask, id)) continue;
    if (!first) out += ", ";
    append_int(out, id);
    first = false;
  }
  out += ']';
}

}  // namespace

std::string to_json(const FdiEvent& event, int n_gyros) {
  std::string out = "{\"time_s\": ";
  append_double(out, ns_to_seconds(event.stamp_ns));
  out += ", \"event\": ";
  append_json_string(out, to_string(event.type));
  switch (event.type) {
    case EventType::kDetected:
    case EventType::kUnisolated:
      out += ", \"gyro\": null, \"test\": ";
      append_json_string(out, event.test);
      out += ", \"statistic\": ";
      if (std::isfinite(event.statistic)) {
        append_double(out, event.statistic);
      } else {
        out += "null";
      }
      break;
    case EventType::kIsolated:
      out += ", \"gyro\": ";
      if (event.gyro) {
        append_int(out, *event.gyro);
      } else {
        out += "null";
      }
      out += ", \"kind\": ";
      append_json_string(out, to_string(event.kind));
      out += ", \"evidence\": ";
      append_json_string(out, event.evidence);
      if (!event.test.empty()) {
        out += ", \"test\": ";
        append_json_string(out, event.test);
      }
      break;
    case EventType::kReconfigured:
    case EventType::kCleared:
    case EventType::kLost:
      out += ", \"gyros\": ";
      append_gyro_list(out, event.gyros, n_gyros);
      break;
    case EventType::kCommand:
      out += ", \"gyro\": ";
      if (event.gyro) {
        append_int(out, *event.gyro);
      } else {
        out += "null";
      }
      out += ", \"gyros\": ";
      append_gyro_list(out, event.gyros, n_gyros);
      out += event.refused ? ", \"accepted\": false" : ", \"accepted\": true";
      break;
  }
  if (!event.detail.empty()) {
    out += ", \"detail\": ";
    append_json_string(out, event.detail);
  }
  out += '}';
  return out;
}

}  // namespace tetra::fdi
