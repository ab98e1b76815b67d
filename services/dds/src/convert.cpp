#include "tetra/dds/convert.hpp"

#include "tetra/core/quaternion.hpp"
#include "tetra/dds/entity.hpp"

namespace tetra::dds {

tetra_Mode to_wire(fdi::Mode mode) {
  switch (mode) {
    case fdi::Mode::kNominal:
      return tetra_MODE_NOMINAL;
    case fdi::Mode::kDegraded:
      return tetra_MODE_DEGRADED;
    case fdi::Mode::kSuspect:
      return tetra_MODE_SUSPECT;
    case fdi::Mode::kLost:
      return tetra_MODE_LOST;
  }
  return tetra_MODE_LOST;
}
fdi::Mode from_wire(tetra_Mode mode) {
  switch (mode) {
    case tetra_MODE_NOMINAL:
      return fdi::Mode::kNominal;
    case tetra_MODE_DEGRADED:
      return fdi::Mode::kDegraded;
    case tetra_MODE_SUSPECT:
      return fdi::Mode::kSuspect;
    case tetra_MODE_LOST:
      return fdi::Mode::kLost;
  }
  return fdi::Mode::kLost;
}

// The IDL enumerators are declared in the same order as the library's enums.
tetra_FaultKind to_wire(fdi::FaultKind kind) {
  return static_cast<tetra_FaultKind>(static_cast<int>(kind));
}
fdi::FaultKind from_wire(tetra_FaultKind kind) {
  const int value = static_cast<int>(kind);
  return value >= 0 && value <= static_cast<int>(fdi::FaultKind::kUnknown)
             ? static_cast<fdi::FaultKind>(value)
             : fdi::FaultKind::kUnknown;
}
tetra_GyroState to_wire(fdi::GyroState state) {
  return static_cast<tetra_GyroState>(static_cast<int>(state));
}
fdi::GyroState from_wire(tetra_GyroState state) {
  const int value = static_cast<int>(state);
  return value >= 0 && value <= static_cast<int>(fdi::GyroState::kExcluded)
             ? static_cast<fdi::GyroState>(value)
             : fdi::GyroState::kAbsent;
}
tetra_EventType to_wire(fdi::EventType type) {
  return static_cast<tetra_EventType>(static_cast<int>(type));
}
fdi::EventType from_wire(tetra_EventType type) {
  const int value = static_cast<int>(type);
  return value >= 0 && value <= static_cast<int>(fdi::EventType::kCalibrationMismatch)
             ? static_cast<fdi::EventType>(value)
             : fdi::EventType::kCommand;
}
static_assert(static_cast<int>(tetra_FAULT_UNKNOWN) == static_cast<int>(fdi::FaultKind::kUnknown));
static_assert(static_cast<int>(tetra_GYRO_EXCLUDED) == static_cast<int>(fdi::GyroState::kExcluded));
static_assert(static_cast<int>(tetra_EVENT_COMMAND) == static_cast<int>(fdi::EventType::kCommand));
static_assert(static_cast<int>(tetra_EVENT_FDI_AVAILABLE) == static_cast<int>(fdi::EventType::kFdiAvailable));
static_assert(static_cast<int>(tetra_EVENT_GAP) == static_cast<int>(fdi::EventType::kGap));
static_assert(static_cast<int>(tetra_EVENT_REFERENCE_ACCEPTED) ==
              static_cast<int>(fdi::EventType::kReferenceAccepted));
static_assert(static_cast<int>(tetra_EVENT_REFERENCE_LATE) ==
              static_cast<int>(fdi::EventType::kReferenceLate));
static_assert(static_cast<int>(tetra_EVENT_NOISE_MODEL) == static_cast<int>(fdi::EventType::kNoiseModel));
static_assert(static_cast<int>(tetra_EVENT_CALIBRATION_MISMATCH) ==
              static_cast<int>(fdi::EventType::kCalibrationMismatch));
static_assert(static_cast<int>(tetra_REFERENCE_REJECTED) == static_cast<int>(fdi::ReferenceState::kRejected));

Status to_wire(const std::string& unit, const fdi::AttitudeEstimate& attitude, tetra_Attitude& out) {
  if (auto status = copy_bounded(out.unit, unit, "unit"); !status) return status;
  out.stamp_ns = attitude.stamp_ns;
  const auto q = to_wxyz(attitude.q_RB);
  for (std::size_t i = 0; i < 4; ++i) out.q_RB[i] = q[i];
  for (int i = 0; i < 3; ++i) {
    out.omega_BR_B_rad_s[i] = attitude.omega_BR_B_rad_s[i];
    out.sigma_rad[i] = attitude.sigma_rad[i];
    out.protection_level_rad[i] = attitude.protection_level_rad[i];
  }
  out.mode = to_wire(attitude.mode);
  out.gyros = attitude.gyros;
  out.fdi_available = attitude.fdi_available;
  return ok_status();
}

fdi::AttitudeEstimate from_wire(const tetra_Attitude& in) {
  fdi::AttitudeEstimate out;
  out.stamp_ns = in.stamp_ns;
  out.q_RB = from_wxyz(in.q_RB[0], in.q_RB[1], in.q_RB[2], in.q_RB[3]);
  for (int i = 0; i < 3; ++i) {
    out.omega_BR_B_rad_s[i] = in.omega_BR_B_rad_s[i];
    out.sigma_rad[i] = in.sigma_rad[i];
    out.protection_level_rad[i] = in.protection_level_rad[i];
  }
  out.mode = from_wire(in.mode);
  out.gyros = in.gyros;
  out.fdi_available = in.fdi_available;
  return out;
}

Status to_wire(const std::string& unit, const fdi::Health& health, const service::AssemblerCounters& counters,
               WireHealth& out) {
  if (auto status = copy_bounded(out.msg.unit, unit, "unit"); !status) return status;
  if (health.gyros.size() > out.gyros.size()) return bad_input("health: more gyros than the wire carries");
  out.msg.stamp_ns = health.stamp_ns;
  out.msg.mode = to_wire(health.mode);
  out.msg.used = health.used;
  for (std::size_t i = 0; i < health.gyros.size(); ++i) {
    out.gyros[i].state = to_wire(health.gyros[i].state);
    out.gyros[i].kind = to_wire(health.gyros[i].kind);
    out.gyros[i].bias_rad_s = health.gyros[i].bias_rad_s;
    out.gyros[i].bias_sigma_rad_s = health.gyros[i].bias_sigma_rad_s;
  }
  out.msg.gyros._buffer = out.gyros.data();
  out.msg.gyros._length = static_cast<std::uint32_t>(health.gyros.size());
  out.msg.gyros._maximum = static_cast<std::uint32_t>(out.gyros.size());
  out.msg.gyros._release = false;
  out.msg.parity_residual = health.parity_residual;
  out.msg.chi2 = health.chi2;
  out.msg.cusum = health.cusum;
  out.msg.chi2_threshold = health.chi2_threshold;
  out.msg.cusum_threshold = health.cusum_threshold;
  out.msg.fdi_available = health.fdi_available;
  out.msg.reference_state = static_cast<tetra_ReferenceState>(static_cast<int>(health.reference_state));
  out.msg.reference_nis = health.reference_nis;
  for (int i = 0; i < 3; ++i) out.msg.protection_level_rad[i] = health.protection_level_rad[i];
  out.msg.references_delayed = health.counters.reference_delayed;
  // Left out: beyond the fusion horizon (the pipeline's), or crowded out before reaching it (the
  // assembler's).
  out.msg.references_too_late = health.counters.reference_too_late + counters.references_crowded_out;
  tetra_SampleCounters& c = out.msg.counters;
  c.epochs_accepted = health.counters.epochs_accepted;
  c.epochs_rejected_time = health.counters.epochs_rejected_time;
  c.samples_accepted = health.counters.samples_accepted;
  c.samples_invalid = health.counters.samples_invalid;
  c.samples_absent = health.counters.samples_absent;
  // References late or waited for in vain, and promised samples that never came, count as late.
  c.samples_late = counters.samples_late + counters.references_late + counters.samples_promised_lost;
  c.samples_duplicate = counters.samples_duplicate;
  c.samples_out_of_order = counters.samples_out_of_order;
  c.samples_gap = counters.samples_gap;
  c.samples_unknown_gyro = counters.samples_unknown_gyro;
  c.samples_other_unit = counters.samples_other_unit;
  c.sensor_restarts = counters.sensor_restarts;
  c.deadlines_missed = counters.deadlines_missed;
  c.liveliness_lost = counters.liveliness_lost;
  c.time_outlier = counters.time_outlier;
  c.seq_discontinuity = counters.seq_discontinuity;
  c.unit_silences = counters.unit_silences;
  return ok_status();
}

HealthView from_wire(const tetra_Health& in) {
  HealthView out;
  out.unit = from_wire(in.unit);
  fdi::Health& h = out.health;
  h.stamp_ns = in.stamp_ns;
  h.mode = from_wire(in.mode);
  h.used = in.used;
  for (std::uint32_t i = 0; i < in.gyros._length; ++i) {
    const tetra_GyroStatus& g = in.gyros._buffer[i];
    h.gyros.push_back({from_wire(g.state), from_wire(g.kind), g.bias_rad_s, g.bias_sigma_rad_s});
  }
  h.parity_residual = in.parity_residual;
  h.chi2 = in.chi2;
  h.cusum = in.cusum;
  h.chi2_threshold = in.chi2_threshold;
  h.cusum_threshold = in.cusum_threshold;
  h.fdi_available = in.fdi_available;
  const int reference_state = static_cast<int>(in.reference_state);
  h.reference_state =
      reference_state >= 0 && reference_state <= static_cast<int>(fdi::ReferenceState::kRejected)
          ? static_cast<fdi::ReferenceState>(reference_state)
          : fdi::ReferenceState::kAbsent;
  h.reference_nis = in.reference_nis;
  for (int i = 0; i < 3; ++i) h.protection_level_rad[i] = in.protection_level_rad[i];
  h.counters.reference_delayed = in.references_delayed;
  h.counters.reference_too_late = in.references_too_late;
  out.reference_horizon_s = in.reference_horizon_s;
  const tetra_SampleCounters& c = in.counters;
  h.counters.epochs_accepted = c.epochs_accepted;
  h.counters.epochs_rejected_time = c.epochs_rejected_time;
  h.counters.samples_accepted = c.samples_accepted;
  h.counters.samples_invalid = c.samples_invalid;
  h.counters.samples_absent = c.samples_absent;
  out.counters.samples_late = c.samples_late;
  out.counters.samples_duplicate = c.samples_duplicate;
  out.counters.samples_out_of_order = c.samples_out_of_order;
  out.counters.samples_gap = c.samples_gap;
  out.counters.samples_unknown_gyro = c.samples_unknown_gyro;
  out.counters.samples_other_unit = c.samples_other_unit;
  out.counters.sensor_restarts = c.sensor_restarts;
  out.events_published = in.events_published;
  out.gyro_writers = in.gyro_writers;
  out.health_period_s = in.health_period_s;
  out.counters.deadlines_missed = c.deadlines_missed;
  out.counters.liveliness_lost = c.liveliness_lost;
  out.counters.time_outlier = c.time_outlier;
  out.counters.seq_discontinuity = c.seq_discontinuity;
  out.counters.unit_silences = c.unit_silences;
  return out;
}

namespace {
//! The text, or as much as fits followed by how much was cut: never cut silently.
template <std::size_t N>
void copy_marked(char (&dest)[N], const std::string& text) {
  std::string shown = text;
  if (shown.size() > N - 1) {
    std::string mark = " [cut: " + std::to_string(text.size()) + " bytes not sent]";
    shown = text.substr(0, N - 1 - mark.size());
    mark = " [cut: " + std::to_string(text.size() - shown.size()) + " bytes not sent]";
    shown = text.substr(0, N - 1 - mark.size()) + mark;
  }
  shown.copy(dest, shown.size());
  dest[shown.size()] = '\0';
}

tetra_RowVerdict verdict_to_wire(fdi::RowVerdict verdict) {
  switch (verdict) {
    case fdi::RowVerdict::kConsistent:
      return tetra_ROW_CONSISTENT;
    case fdi::RowVerdict::kRejected:
      return tetra_ROW_REJECTED;
    case fdi::RowVerdict::kNoCall:
      break;
  }
  return tetra_ROW_NO_CALL;
}

fdi::RowVerdict verdict_from_wire(tetra_RowVerdict verdict) {
  switch (verdict) {
    case tetra_ROW_CONSISTENT:
      return fdi::RowVerdict::kConsistent;
    case tetra_ROW_REJECTED:
      return fdi::RowVerdict::kRejected;
    default:
      return fdi::RowVerdict::kNoCall;
  }
}

void ledger_to_wire(const std::vector<fdi::LedgerRow>& ledger, WireEvent& out) {
  const std::size_t n = std::min(ledger.size(), out.rows.size());
  for (std::size_t i = 0; i < n; ++i) {
    const fdi::LedgerRow& r = ledger[i];
    tetra_LedgerRow& w = out.rows[i];
    w = tetra_LedgerRow{};
    std::string(fdi::to_string(r.source)).copy(w.source, sizeof w.source - 1);
    std::string(fdi::to_string(fdi::info(r.source).unit)).copy(w.unit, sizeof w.unit - 1);
    w.hypothesis = r.hypothesis;
    w.verdict = verdict_to_wire(r.verdict);
    w.dof = r.dof;
    w.statistic = r.statistic;
    w.threshold = r.threshold;
    w.accept = r.accept;
  }
  out.msg.ledger._buffer = out.rows.data();
  out.msg.ledger._length = static_cast<std::uint32_t>(n);
  out.msg.ledger._maximum = static_cast<std::uint32_t>(out.rows.size());
  out.msg.ledger._release = false;
  out.msg.ledger_dropped = static_cast<std::uint16_t>(std::min<std::size_t>(ledger.size() - n, 65535));
}

std::vector<fdi::LedgerRow> ledger_from_wire(const tetra_FdiEvent2& in) {
  std::vector<fdi::LedgerRow> ledger;
  for (std::uint32_t i = 0; i < in.ledger._length && in.ledger._buffer != nullptr; ++i) {
    const tetra_LedgerRow& w = in.ledger._buffer[i];
    fdi::LedgerRow r;
    if (!fdi::evidence_source_from_string(from_wire(w.source), r.source)) continue;  // a source unknown here
    r.hypothesis = w.hypothesis;
    r.verdict = verdict_from_wire(w.verdict);
    r.dof = w.dof;
    r.statistic = w.statistic;
    r.threshold = w.threshold;
    r.accept = w.accept;
    ledger.push_back(r);
  }
  return ledger;
}
}  // namespace

Status to_wire(const EventView& view, WireEvent& wire) {
  tetra_FdiEvent2& out = wire.msg;
  if (auto status = copy_bounded(out.unit, view.unit, "unit"); !status) return status;
  const fdi::FdiEvent& e = view.event;
  // A reference event's test is why the reference was rejected (nis, lag, bias, jump).
  const bool reference_event =
      e.type == fdi::EventType::kReferenceRejected || e.type == fdi::EventType::kReferenceAccepted;
  const std::string test = reference_event ? fdi::to_string(e.why) : fdi::to_string(e.test);
  if (auto status = copy_bounded(out.test, test, "event test"); !status) return status;
  if (auto status = copy_bounded(out.evidence, std::string(fdi::to_string(e.evidence)), "event evidence");
      !status)
    return status;
  copy_marked(out.detail, e.detail);
  ledger_to_wire(e.ledger, wire);
  out.event_seq = view.event_seq;
  out.command_id = view.command_id;
  out.stamp_ns = e.stamp_ns;
  out.type = to_wire(e.type);
  out.gyro = static_cast<std::int16_t>(e.gyro.value_or(0));
  out.statistic = e.statistic;
  out.kind = to_wire(e.kind);
  out.gyros = e.gyros;
  out.refused = e.refused();
  out.command = view.command.kind;
  out.force = view.command.force;
  if (auto status = copy_bounded(out.operator_id, view.command.operator_id, "operator id"); !status)
    return status;
  return copy_bounded(out.origin, view.command.origin, "command origin");
}

const char* to_string(tetra_CommandKind kind) {
  switch (kind) {
    case tetra_COMMAND_EXCLUDE:
      return "exclude";
    case tetra_COMMAND_REINSTATE:
      return "reinstate";
    default:
      return "reset";
  }
}

namespace {
//! A command's outcome from its acknowledgement text ("exclude 2: already excluded"); a refusal whose text
//! does not say which is taken as the only refusal that changes nothing on purpose.
fdi::CommandOutcome outcome_from_wire(const std::string& detail, bool refused) {
  const auto colon = detail.find(": ");
  if (colon != std::string::npos) {
    if (auto o = fdi::command_outcome_from_string(std::string_view(detail).substr(colon + 2))) return *o;
  }
  return refused ? fdi::CommandOutcome::kRefusedUnobservable : fdi::CommandOutcome::kDone;
}
}  // namespace

EventView from_wire(const tetra_FdiEvent2& in) {
  EventView out;
  out.unit = from_wire(in.unit);
  out.event_seq = in.event_seq;
  out.command_id = in.command_id;
  fdi::FdiEvent& e = out.event;
  e.stamp_ns = in.stamp_ns;
  e.type = from_wire(in.type);
  if (in.gyro > 0) e.gyro = in.gyro;
  e.test = fdi::detection_test_from_string(from_wire(in.test));
  if (e.type == fdi::EventType::kReferenceRejected)
    e.why = fdi::reference_check_from_string(from_wire(in.test));
  e.statistic = in.statistic;
  e.kind = from_wire(in.kind);
  e.evidence = fdi::evidence_from_string(from_wire(in.evidence));
  e.gyros = in.gyros;
  e.detail = from_wire(in.detail);
  e.outcome = outcome_from_wire(e.detail, in.refused);
  e.ledger = ledger_from_wire(in);
  out.command = {in.command, in.force, from_wire(in.operator_id), from_wire(in.origin)};
  return out;
}

}  // namespace tetra::dds
