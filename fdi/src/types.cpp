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
    case EventType::kFdiUnavailable:
      return "fdi_unavailable";
    case EventType::kFdiAvailable:
      return "fdi_available";
    case EventType::kGap:
      return "gap";
    case EventType::kReferenceRejected:
      return "reference_rejected";
    case EventType::kReferenceAccepted:
      return "reference_accepted";
    case EventType::kReferenceLate:
      return "reference_late";
    case EventType::kNoiseModel:
      return "noise_model";
    case EventType::kCalibrationMismatch:
      return "calibration_mismatch";
  }
  return "command";
}

const char* to_string(ReferenceState state) {
  switch (state) {
    case ReferenceState::kAbsent:
      return "absent";
    case ReferenceState::kAccepted:
      return "accepted";
    case ReferenceState::kRejected:
      return "rejected";
  }
  return "absent";
}

const char* to_string(ReferenceCheck check) {
  switch (check) {
    case ReferenceCheck::kNone:
      return "";
    case ReferenceCheck::kNis:
      return "nis";
    case ReferenceCheck::kLag:
      return "lag";
    case ReferenceCheck::kBias:
      return "bias";
    case ReferenceCheck::kJump:
      return "jump";
    case ReferenceCheck::kStep:
      return "step";
  }
  return "";
}

ReferenceCheck reference_check_from_string(std::string_view text) {
  for (const ReferenceCheck c : {ReferenceCheck::kNis, ReferenceCheck::kLag, ReferenceCheck::kBias,
                                 ReferenceCheck::kJump, ReferenceCheck::kStep}) {
    if (text == to_string(c)) return c;
  }
  return ReferenceCheck::kNone;
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

const char* to_string(DetectionTest test) {
  switch (test) {
    case DetectionTest::kNone:
      return "";
    case DetectionTest::kChi2:
      return "chi2";
    case DetectionTest::kCusum:
      return "cusum";
    case DetectionTest::kSignature:
      return "signature";
    case DetectionTest::kOnset:
      return "onset";
    case DetectionTest::kReference:
      return "reference";
    case DetectionTest::kLevel:
      return "level";
  }
  return "";
}

DetectionTest detection_test_from_string(std::string_view text) {
  for (auto t : {DetectionTest::kChi2, DetectionTest::kCusum, DetectionTest::kSignature,
                 DetectionTest::kOnset, DetectionTest::kReference, DetectionTest::kLevel}) {
    if (text == to_string(t)) return t;
  }
  return DetectionTest::kNone;
}

namespace {
constexpr std::array<const char*, 11> kEvidenceNames = {
    "",      "invalid",   "timeout", "repeated", "zero", "variance", "noise-level", "recurring-spikes",
    "onset", "reference", "glt"};
}  // namespace

const char* to_string(Evidence evidence) {
  const auto i = static_cast<std::size_t>(evidence);
  return i < kEvidenceNames.size() ? kEvidenceNames[i] : "";
}

Evidence evidence_from_string(std::string_view text) {
  for (std::size_t i = 1; i < kEvidenceNames.size(); ++i) {
    if (text == kEvidenceNames[i]) return static_cast<Evidence>(i);
  }
  return Evidence::kNone;
}

const char* to_string(CommandVerb verb) {
  switch (verb) {
    case CommandVerb::kExclude:
      return "exclude";
    case CommandVerb::kReinstate:
      return "reinstate";
    case CommandVerb::kReset:
      return "reset";
  }
  return "reset";
}

const char* to_string(CommandOutcome outcome) {
  switch (outcome) {
    case CommandOutcome::kDone:
      return "done";
    case CommandOutcome::kNoSuchGyro:
      return "rejected, no such gyro";
    case CommandOutcome::kAlreadyExcluded:
      return "already excluded";
    case CommandOutcome::kNotExcluded:
      return "not excluded";
    case CommandOutcome::kRefusedUnobservable:
      return "refused, the rest could not determine attitude (force overrides)";
  }
  return "done";
}

std::optional<CommandOutcome> command_outcome_from_string(std::string_view text) {
  for (auto o : {CommandOutcome::kDone, CommandOutcome::kNoSuchGyro, CommandOutcome::kAlreadyExcluded,
                 CommandOutcome::kNotExcluded, CommandOutcome::kRefusedUnobservable}) {
    if (text == to_string(o)) return o;
  }
  return std::nullopt;
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

//! `, "gyro": ` and the gyro, or null.
void append_gyro(std::string& out, const std::optional<int>& gyro) {
  out += ", \"gyro\": ";
  if (gyro) {
    append_int(out, *gyro);
  } else {
    out += "null";
  }
}

//! `, "statistic": ` and the value, or null when it is not finite.
void append_statistic(std::string& out, double statistic) {
  out += ", \"statistic\": ";
  if (std::isfinite(statistic)) {
    append_double(out, statistic);
  } else {
    out += "null";
  }
}

}  // namespace

namespace {
//! The gyros whose hypotheses an event's rows judge: the gyros that were in use.
std::uint32_t gyros_of(const FdiEvent& event) {
  std::uint32_t active = 0;
  for (const LedgerRow& row : event.ledger)
    if (row.hypothesis != kHypothesisNone && row.hypothesis <= 32)
      active |= std::uint32_t{1} << (row.hypothesis - 1U);
  return active;
}
}  // namespace

int ruling_of(const FdiEvent& event) {
  bool reference = false;
  for (const LedgerRow& row : event.ledger) reference |= row.hypothesis == kHypothesisReference;
  return arbitrate(event.ledger.data(), event.ledger.data() + event.ledger.size(), gyros_of(event),
                   reference);
}

ReferenceDecision reference_ruling_of(const FdiEvent& event) {
  return arbitrate_reference(event.ledger.data(), event.ledger.data() + event.ledger.size(), gyros_of(event));
}

bool calibration_ruling_of(const FdiEvent& event) {
  return arbitrate_calibration(event.ledger.data(), event.ledger.data() + event.ledger.size(),
                               gyros_of(event));
}

bool noise_ruling_of(const FdiEvent& event) {
  for (const LedgerRow& row : event.ledger) {
    const bool model_rejected =
        row.source == EvidenceSource::kParitySpread || row.source == EvidenceSource::kParityBlockMatch;
    if (model_rejected && row.hypothesis == kHypothesisNone && row.verdict == RowVerdict::kRejected)
      return true;
  }
  return reference_ruling_of(event) == ReferenceDecision::kMatchDrift;
}

std::string to_json(const FdiEvent& event, int n_gyros) {
  std::string out = "{\"time_s\": ";
  append_double(out, ns_to_seconds(event.stamp_ns));
  out += ", \"event\": ";
  append_json_string(out, to_string(event.type));
  switch (event.type) {
    case EventType::kDetected:
    case EventType::kUnisolated:
      append_gyro(out, event.gyro);  // a detection may name a gyro without excluding it (three gyros)
      out += ", \"test\": ";
      append_json_string(out, to_string(event.test));
      append_statistic(out, event.statistic);
      break;
    case EventType::kIsolated:
      append_gyro(out, event.gyro);
      out += ", \"kind\": ";
      append_json_string(out, to_string(event.kind));
      out += ", \"evidence\": ";
      append_json_string(out, to_string(event.evidence));
      if (event.test != DetectionTest::kNone) {
        out += ", \"test\": ";
        append_json_string(out, to_string(event.test));
      }
      break;
    case EventType::kReferenceRejected:
    case EventType::kReferenceAccepted:
      if (event.why != ReferenceCheck::kNone) {
        out += ", \"why\": ";
        append_json_string(out, to_string(event.why));
      }
      append_statistic(out, event.statistic);
      break;
    case EventType::kReconfigured:
    case EventType::kCleared:
    case EventType::kLost:
    case EventType::kFdiUnavailable:
    case EventType::kFdiAvailable:
      out += ", \"gyros\": ";
      append_gyro_list(out, event.gyros, n_gyros);
      break;
    case EventType::kReferenceLate:
      out += ", \"late_s\": ";
      append_double(out, event.statistic);
      break;
    case EventType::kGap:
      out += ", \"length_s\": ";
      append_double(out, event.statistic);
      break;
    case EventType::kNoiseModel:
    case EventType::kCalibrationMismatch:
      append_statistic(out, event.statistic);
      break;
    case EventType::kCommand:
      append_gyro(out, event.gyro);
      out += ", \"gyros\": ";
      append_gyro_list(out, event.gyros, n_gyros);
      out += event.refused() ? ", \"accepted\": false" : ", \"accepted\": true";
      break;
  }
  if (!event.detail.empty()) {
    out += ", \"detail\": ";
    append_json_string(out, event.detail);
  }
  if (!event.ledger.empty()) {
    out += ", \"ledger\": [";
    for (std::size_t i = 0; i < event.ledger.size(); ++i) {
      if (i > 0) out += ", ";
      append_json(out, event.ledger[i]);
    }
    out += ']';
  }
  out += '}';
  return out;
}

}  // namespace tetra::fdi
