#include "tetra/sim/fault.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <utility>
#include <vector>

#include "tetra/core/csv.hpp"
#include "text.hpp"

namespace tetra::sim {

namespace {

constexpr std::pair<FaultKind, std::string_view> kFaultKindNames[] = {
    {FaultKind::kBias, "bias"},   {FaultKind::kRamp, "ramp"},       {FaultKind::kScale, "scale"},
    {FaultKind::kStuck, "stuck"}, {FaultKind::kZero, "zero"},       {FaultKind::kNoise, "noise"},
    {FaultKind::kSpike, "spike"}, {FaultKind::kDropout, "dropout"}, {FaultKind::kInvalid, "invalid"}};

std::optional<double> to_double(std::string_view text) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

bool kind_takes_size(FaultKind kind) {
  return kind == FaultKind::kBias || kind == FaultKind::kRamp || kind == FaultKind::kScale ||
         kind == FaultKind::kNoise || kind == FaultKind::kSpike;
}

std::optional<FaultKind> fault_kind_from_name(std::string_view name) {
  for (const auto& [k, text] : kFaultKindNames) {
    if (text == name) return k;
  }
  return std::nullopt;
}

std::string_view fault_kind_name(FaultKind kind) {
  for (const auto& [k, name] : kFaultKindNames) {
    if (k == kind) return name;
  }
  return "unknown";
}

namespace {

// The fields of a fault spec as read so far.
struct FaultFields {
  FaultSpec fault;
  bool has_gyro = false;
  bool has_kind = false;
  bool has_at = false;
  std::optional<double> size;
};

Status read_gyro(std::string_view value, const std::string& where, FaultFields& f) {
  int gyro = 0;
  auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), gyro);
  if (ec != std::errc() || ptr != value.data() + value.size() || gyro < 1) {
    return bad_input(where + "gyro: expected a gyro number 1..N, got '" + std::string(value) + "'");
  }
  f.fault.gyro = gyro;
  f.has_gyro = true;
  return ok_status();
}

Status read_kind(std::string_view value, const std::string& where, FaultFields& f) {
  const auto kind = fault_kind_from_name(value);
  if (!kind) {
    return bad_input(where + "kind: unknown kind '" + std::string(value) +
                     "' (known: bias, ramp, scale, stuck, zero, noise, spike, dropout, invalid)");
  }
  f.fault.kind = *kind;
  f.has_kind = true;
  return ok_status();
}

// at, until or size.
Status read_number(const std::string& key, std::string_view value, const std::string& where, FaultFields& f) {
  const auto number = to_double(value);
  if (!number) return bad_input(where + key + ": expected a finite number, got '" + std::string(value) + "'");
  if (key == "at") {
    f.fault.at_s = *number;
    f.has_at = true;
  } else if (key == "until") {
    f.fault.until_s = *number;
  } else {
    f.size = *number;
  }
  return ok_status();
}

Status read_field(const std::string& key, std::string_view value, const std::string& where, FaultFields& f) {
  if (key == "gyro") return read_gyro(value, where, f);
  if (key == "kind") return read_kind(value, where, f);
  if (key == "at" || key == "until" || key == "size") return read_number(key, value, where, f);
  return bad_input(where + "unknown field '" + key + "' (fields: gyro, kind, at, size, until)");
}

// The comma-separated key=value fields, each key at most once.
Status read_fields(std::string_view text, const std::string& where, FaultFields& f) {
  std::vector<std::string> seen;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t comma = text.find(',', pos);
    if (comma == std::string_view::npos) comma = text.size();
    const std::string_view field = text.substr(pos, comma - pos);
    pos = comma + 1;
    const std::size_t eq = field.find('=');
    if (eq == std::string_view::npos) {
      return bad_input(where + "field '" + std::string(field) + "' is not key=value");
    }
    const std::string key(field.substr(0, eq));
    if (std::find(seen.begin(), seen.end(), key) != seen.end())
      return bad_input(where + key + ": given twice");
    seen.push_back(key);
    if (Status st = read_field(key, field.substr(eq + 1), where, f); !st) return st;
    if (comma == text.size()) break;
  }
  return ok_status();
}

// gyro, kind and at given; the times in order.
Status check_required(const FaultFields& f, const std::string& where) {
  if (!f.has_gyro) return bad_input(where + "gyro is missing");
  if (!f.has_kind) return bad_input(where + "kind is missing");
  if (!f.has_at) return bad_input(where + "at is missing");
  if (f.fault.at_s < 0.0) return bad_input(where + "at must not be negative");
  if (f.fault.until_s && *f.fault.until_s <= f.fault.at_s) return bad_input(where + "until must be after at");
  return ok_status();
}

// A size exactly for the kinds that take one, in the kind's range; until not for a spike.
Status check_size(FaultFields& f, const std::string& where) {
  FaultSpec& fault = f.fault;
  if (kind_takes_size(fault.kind)) {
    if (!f.size)
      return bad_input(where + "size is required for kind " + std::string(fault_kind_name(fault.kind)));
    fault.size = *f.size;
    if (Status st = check_fault_size(fault.kind, fault.size); !st)
      return bad_input(where + "size: " + st.error().message);
  } else if (f.size) {
    return bad_input(where + "size has no meaning for kind " + std::string(fault_kind_name(fault.kind)));
  }
  if (fault.kind == FaultKind::kSpike && fault.until_s) {
    return bad_input(where + "until has no meaning for a spike (one sample at 'at')");
  }
  return ok_status();
}

}  // namespace

Status check_fault_size(FaultKind kind, double size) {
  if (!std::isfinite(size) || std::abs(size) > kMaxFaultSize)
    return bad_input("must be finite and at most " + number_text(kMaxFaultSize) + " in magnitude");
  if (kind == FaultKind::kNoise && size < 0.0) return bad_input("a noise multiplier must not be negative");
  if (kind == FaultKind::kScale && size <= -1.0) return bad_input("a relative scale change must be above -1");
  return ok_status();
}

Result<FaultSpec> parse_fault_spec(std::string_view text) {
  const std::string where = "fault '" + std::string(text) + "': ";
  FaultFields f;
  if (Status st = read_fields(text, where, f); !st) return st.error();
  if (Status st = check_required(f, where); !st) return st.error();
  if (Status st = check_size(f, where); !st) return st.error();
  return f.fault;
}

std::string format_fault_spec(const FaultSpec& fault) {
  std::string out =
      "gyro=" + std::to_string(fault.gyro) + ",kind=" + std::string(fault_kind_name(fault.kind)) + ",at=";
  append_double(out, fault.at_s);
  if (kind_takes_size(fault.kind)) {
    out += ",size=";
    append_double(out, fault.size);
  }
  if (fault.until_s) {
    out += ",until=";
    append_double(out, *fault.until_s);
  }
  return out;
}

}  // namespace tetra::sim
